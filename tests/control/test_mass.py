"""The mass estimate (control/mass.py) against the first-order filter's closed form, its
bounds, its freeze and the model's hysteresis; and the controller's model weighing a
seated robot (control/model.py)."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import ControllerConfig, Scenario
from drake_standup.control.mass import RESCALE_ABOVE, mass_estimate, next_mass_state
from drake_standup.control.model import ControllerModel, contact_specs
from drake_standup.standup.contact_schedule import contact_commands
from drake_standup.world.scene import add_scene, set_seated_state

BOUNDS = (0.7, 1.3)


def test_the_estimate_follows_a_first_order_filter():
    """A weight 10 % above the model's measured every tick: s_k = 1.1 - 0.1 (1 - b)^k."""
    scale, began, blend = 1.0, False, 0.04 / 0.3
    for k in range(1, 60):
        scale, began = mass_estimate(scale, began, 1, 1.1 * 300.0, 300.0, blend, bounds=BOUNDS)
        assert scale == pytest.approx(1.1 - 0.1 * (1.0 - blend) ** k, rel=1e-12)
    assert not began


def test_the_estimate_is_bounded_frozen_once_the_stand_up_begins_or_off():
    assert mass_estimate(1.0, False, 1, 3.0 * 300.0, 300.0, 1.0, bounds=BOUNDS)[0] == 1.3
    assert mass_estimate(1.0, False, 1, 0.0, 300.0, 1.0, bounds=BOUNDS)[0] == 0.7
    # State 2 seen: frozen from this tick on, whatever the pads then carry.
    assert mass_estimate(1.05, False, 2, 600.0, 300.0, 0.5, bounds=BOUNDS) == (1.05, True)
    assert mass_estimate(1.05, True, 1, 600.0, 300.0, 0.5, bounds=BOUNDS) == (1.05, True)
    # No filter (controller.mass_estimation_filter_s: 0): the nominal model.
    assert mass_estimate(1.0, False, 1, 600.0, 300.0, 0.0, bounds=BOUNDS) == (1.0, False)


def test_the_model_follows_the_estimate_past_the_hysteresis():
    state = np.array([1.0, 0.0, 1.0])
    small = 1.0 + 0.5 * RESCALE_ABOVE  # weight -> scale in one tick (blend 1)
    state = next_mass_state(state, 1, small * 300.0, 300.0, 1.0, BOUNDS)
    np.testing.assert_allclose(state, [small, 0.0, 1.0], rtol=1e-15)
    large = 1.0 + 2.0 * RESCALE_ABOVE
    state = next_mass_state(state, 1, large * 300.0, 300.0, 1.0, BOUNDS)
    np.testing.assert_allclose(state, [large, 0.0, large], rtol=1e-15)


def test_the_controllers_model_weighs_the_seated_robot():
    """The model, its inputs fixed: the pads carry 1.08 of the model's weight and the hands
    pull 20 N up; after 1 s of 4 ms ticks (tau 0.3 s) the model's mass is (1.08 + 20 N /
    m g) of nominal to 1e-4 (the filter's closed form), in the terms the QP reads; once
    state 2 is seen it stays."""
    scenario = Scenario()
    scene = add_scene(DiagramBuilder(), scenario, pd_gains=None, visuals=False)
    plant, robot = scene.plant, scene.robot
    config = ControllerConfig()
    model = ControllerModel(plant, robot, contact_specs(plant, robot, config), config, 0.004)
    plant_context = plant.CreateDefaultContext()
    set_seated_state(scene, plant_context)
    m = plant.CalcTotalMass(plant_context, [robot.model_instance])
    g = -plant.gravity_field().gravity_vector()[2]
    hands = np.zeros(12)
    hands[5] = hands[11] = 10.0
    weighing = np.array(ControllerModel.INITIAL_WEIGHING)
    ticks = 1 + int(round(1.0 / 0.004))  # the initialization tick, then one per period
    for _ in range(ticks):
        weighing = model.next_weighing(weighing, 1, hands, 1.08 * m * g)
    target = 1.08 + 20.0 / (m * g)
    expected = target - (target - 1.0) * (1.0 - 0.004 / 0.3) ** ticks
    estimate = weighing[0]
    assert estimate == pytest.approx(expected, abs=RESCALE_ABOVE)
    seated = contact_commands(config, np.full(3, np.nan), np.zeros(3), None, "held")
    x = plant.GetPositionsAndVelocities(plant_context, robot.model_instance)
    terms = model.terms(x, seated, hands, float(weighing[2]))
    assert terms.mass_kg == pytest.approx(expected * m, rel=2 * RESCALE_ABOVE)
    for _ in range(ticks):
        weighing = model.next_weighing(weighing, 2, hands, 0.5 * m * g)
    assert weighing[0] == estimate
