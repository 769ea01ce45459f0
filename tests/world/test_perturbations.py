"""Perturbations: pushes reach the plant (and only the plant) with the right
impulse, the wrench noise is a reproducible held Gaussian on the force rows,
the mass and friction errors change the simulated world only, and with the
defaults the diagram is the one without perturbations."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.common.value import Value
from pydrake.geometry import Role
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CalcContactFrictionFromSurfaceProperties,
    CoulombFriction,
    ExternallyAppliedSpatialForce,
    ExternallyAppliedSpatialForceMultiplexer,
    MultibodyPlantConfig,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantValueSource, ConstantVectorSource, PassThrough

from drake_standup.config import HumanConfig, Pull, Push, Scenario, ScenarioError
from drake_standup.config.chair import SEATED_JOINTS
from drake_standup.config.resources import model_file
from drake_standup.helper.hands import HumanWrenchSource
from drake_standup.robot.icub import ContactModel, add_icub
from drake_standup.sim.diagram import build_diagram
from drake_standup.sim.simulate import simulate
from drake_standup.world import perturbations
from drake_standup.world.perturbations import (
    NoisyWrenchSensor,
    PushSource,
    apply_model_errors,
    scale_friction,
)
from drake_standup.world.scene import set_seated_state

PUSHES = [
    Push(body="chest", start_s=0.5, duration_s=0.2, force_N=[30.0, -5.0, 2.0]),
    Push(body="l_upper_leg", start_s=0.6, duration_s=0.3, force_N=[0.0, 12.0, -4.0]),
]
PULL = Pull(hand="right", start_s=0.0, duration_s=2.0, ramp_s=0.0, force_N=[7.0, 0.0, 3.0])


def _pushes_at(t: float) -> dict[str, np.ndarray]:
    """Body -> expected push force at t, written out from PUSHES' windows."""
    forces = {}
    if 0.5 <= t < 0.7:
        forces["chest"] = np.array([30.0, -5.0, 2.0])
    if 0.6 <= t < 0.9:
        forces["l_upper_leg"] = np.array([0.0, 12.0, -4.0])
    return forces


def _scenario(**perturbation) -> Scenario:
    scenario = Scenario()
    for key, value in perturbation.items():
        setattr(scenario.perturbation, key, value)
    return scenario


# --- Defaults ------------------------------------------------------------------


def _systems(diagram, prefix: str = "") -> dict[str, object]:
    """Every system of diagram and of the diagrams inside it, by path (box/name)."""
    found = {}
    for system in diagram.GetSystems():
        found[prefix + system.get_name()] = system
        if isinstance(system, Diagram):
            found |= _systems(system, f"{prefix}{system.get_name()}/")
    return found


DEFAULT_STATION = {
    f"station/{name}"
    for name in (
        "plant",
        "scene_graph",
        "contact_forces",
        "pad_impulses",
        "seat_pad_normal_forces_N",
        "pads_vertical_force_N",
        "hand_wrench_sensor",
        "sensing",
    )
}


def test_defaults_add_no_perturbation_system():
    """The default station: the plant, the pads' forces and sensors, the hands' sensor a
    pass-through; nothing pushes; no push force is logged."""
    built = build_diagram(Scenario())
    systems = _systems(built.diagram)
    station = {name for name in systems if name.startswith("station/")}
    assert station == DEFAULT_STATION
    assert isinstance(systems["station/hand_wrench_sensor"], PassThrough)
    assert "push_force_W" not in built.logs
    # Every proximity geometry keeps its file's friction (all 1.0).
    inspector = built.station.scene.scene_graph.model_inspector()
    for gid in inspector.GetAllGeometryIds(Role.kProximity):
        mu = inspector.GetProximityProperties(gid).GetProperty("material", "coulomb_friction")
        assert (mu.static_friction(), mu.dynamic_friction()) == (1.0, 1.0)


def test_all_perturbations_add_their_systems_only():
    """Pushes and sensor noise add the push source and the forces' multiplexer to the
    station, the noisy hands' sensor in place of the pass-through, and the push force's
    logger; nothing else changes."""
    default = set(_systems(build_diagram(Scenario()).diagram))
    scenario = _scenario(pushes=PUSHES, hand_wrench_noise_N=1.0)
    systems = _systems(build_diagram(scenario).diagram)
    assert set(systems) - default == {
        "station/pushes",
        "station/applied_forces",
        "log_push_force_W",
    }
    assert default <= set(systems)
    assert isinstance(systems["station/hand_wrench_sensor"], NoisyWrenchSensor)


# --- Pushes --------------------------------------------------------------------


def test_unknown_push_body_is_a_scenario_error():
    scenario = _scenario(pushes=[Push(body="chest"), Push(body="xyz")])
    with pytest.raises(ScenarioError) as err:
        build_diagram(scenario)
    message = str(err.value)
    assert message.startswith("perturbation.pushes[1].body: 'xyz' unknown; accepted: ")
    assert "\n" not in message
    assert "root_link" in message and "chest" in message and "l_hand" in message
    scenario = _scenario(pushes=[Push(body="torso")])
    with pytest.raises(ScenarioError, match=r"^perturbation\.pushes\[0\]\.body: 'torso'"):
        build_diagram(scenario)


def test_plant_gets_human_and_push_forces_and_sensors_only_the_human():
    """The multiplexed plant input: the human's pull on the right hand plus the
    pushes active at t, on their bodies' origins; the measured hand wrenches
    and the logged push_force_W, the pull alone and the pushes' sum."""
    scenario = _scenario(pushes=PUSHES)
    scenario.human = HumanConfig(pulls=[PULL])
    built = build_diagram(scenario)
    plant, robot = built.station.plant, built.station.robot
    root = built.diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(root)
    hand = robot.frame(plant, "r_hand")
    bodies = {
        plant.GetBodyByName(name, robot.model_instance).index(): name
        for name in ("chest", "l_upper_leg")
    }
    systems = _systems(built.diagram)
    human, pushes = systems["human"], systems["station/pushes"]
    windows_seen = set()
    for t in (0.1, 0.4999, 0.5, 0.55, 0.6, 0.65, 0.6999, 0.7, 0.8, 0.8999, 0.9, 1.5):
        root.SetTime(t)
        applied = plant.get_applied_spatial_force_input_port().Eval(plant_context)
        got_pushes, got_pull = {}, []
        for f in applied:
            assert not f.F_Bq_W.rotational().any()
            if f.body_index == hand.body().index():
                got_pull.append(f.F_Bq_W.translational())
                np.testing.assert_array_equal(
                    f.p_BoBq_B, hand.GetFixedPoseInBodyFrame().translation()
                )
            else:
                np.testing.assert_array_equal(f.p_BoBq_B, np.zeros(3))  # body origin
                got_pushes[bodies[f.body_index]] = f.F_Bq_W.translational()
        expected = _pushes_at(t)
        windows_seen.add(tuple(sorted(expected)))
        assert set(got_pushes) == set(expected), t
        for name, force in expected.items():
            np.testing.assert_array_equal(got_pushes[name], force)
        np.testing.assert_array_equal(got_pull, [PULL.force_N])
        total = pushes.GetOutputPort("push_force_W").Eval(pushes.GetMyContextFromRoot(root))
        np.testing.assert_array_equal(total, sum(expected.values(), np.zeros(3)))
        # The wrist sensors measure the pull only.
        wrenches = human.GetOutputPort("hand_wrenches_W").Eval(human.GetMyContextFromRoot(root))
        np.testing.assert_array_equal(wrenches, [0, 0, 0, 0, 0, 0, 0, 0, 0, 7.0, 0, 3.0])
        sensing = systems["station/sensing"]
        measured = sensing.GetInputPort("hand_wrenches_W").Eval(sensing.GetMyContextFromRoot(root))
        np.testing.assert_array_equal(measured, wrenches)
    assert windows_seen == {(), ("chest",), ("chest", "l_upper_leg"), ("l_upper_leg",)}
    assert "push_force_W" in built.logs


def test_push_and_pull_change_momentum_by_their_impulse():
    """Zero gravity, no contact, a limp floating robot pushed on the chest and
    the thigh and pulled on a hand through the multiplexer: its linear momentum
    changes by the impulse sum F(t_n) dt, and its angular momentum about the
    world origin by sum p_WBq(t_n) x F(t_n) dt, with p_WBq each force's point
    (body origins, the hand frame) at the step's start (Newton-Euler). The
    discrete step's O(dt) error is well under 1% (see test_human.py)."""
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlant(MultibodyPlantConfig(time_step=1e-3), builder)
    robot = add_icub(plant, visuals=False, contact=ContactModel())
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    human = builder.AddSystem(HumanWrenchSource(plant, robot, HumanConfig(pulls=[PULL])))
    pushes = builder.AddSystem(PushSource(plant, robot, PUSHES))
    mux = builder.AddSystem(ExternallyAppliedSpatialForceMultiplexer(2))
    builder.Connect(human.GetOutputPort("spatial_forces"), mux.get_input_port(0))
    builder.Connect(pushes.GetOutputPort("spatial_forces"), mux.get_input_port(1))
    builder.Connect(mux.get_output_port(), plant.get_applied_spatial_force_input_port())
    builder.Connect(
        plant.get_state_output_port(robot.model_instance), human.GetInputPort("robot_state")
    )
    zero = builder.AddSystem(ConstantVectorSource(np.zeros(plant.num_actuated_dofs())))
    builder.Connect(zero.get_output_port(), plant.get_actuation_input_port())
    simulator = Simulator(builder.Build())
    root = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(root)
    plant.SetFreeBodyPose(
        plant_context, plant.GetBodyByName("root_link"), RigidTransform([0, 0, 3])
    )
    # The seated joint angles, inside the joint limits: the default (zero)
    # elbows are outside theirs and would snap in over the first steps.
    seated = SEATED_JOINTS
    for name in robot.joint_names:
        joint = plant.GetJointByName(name)
        lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        joint.set_angle(plant_context, float(np.clip(seated.get(name, 0.0), lower, upper)))
    points = {name: plant.GetBodyByName(name).body_frame() for name in ("chest", "l_upper_leg")}
    hand = robot.frame(plant, "r_hand")
    dt, n_steps = 1e-3, 1000
    impulse, moment_impulse = np.zeros(3), np.zeros(3)
    for n in range(n_steps):
        t = n * dt
        forces = [(points[name], f) for name, f in _pushes_at(t).items()]
        if t > PULL.start_s:  # the pull's window is open: (start, start + duration)
            forces.append((hand, np.array(PULL.force_N)))
        for frame, f in forces:
            p = frame.CalcPoseInWorld(plant_context).translation()
            impulse += f * dt
            moment_impulse += np.cross(p, f) * dt
        simulator.AdvanceTo((n + 1) * dt)
    mass = plant.CalcTotalMass(plant_context)
    momentum = mass * plant.CalcCenterOfMassTranslationalVelocityInWorld(plant_context)
    angular = plant.CalcSpatialMomentumInWorldAboutPoint(plant_context, np.zeros(3))
    # The pushes' impulses are 6.1 and 3.8 N s; the errors measured are 0.05%.
    # A push on the wrong body, sign or axis is off by far more than 0.3%.
    assert np.linalg.norm(impulse - 0.999 * np.array(PULL.force_N)) > 5.0
    assert np.linalg.norm(momentum - impulse) < 0.003 * np.linalg.norm(impulse)
    np.testing.assert_allclose(angular.translational(), momentum, rtol=1e-9, atol=1e-9)
    err = np.linalg.norm(angular.rotational() - moment_impulse)
    assert err < 0.003 * np.linalg.norm(moment_impulse)


# --- Hand wrench noise -----------------------------------------------------------


def _measured(sensor: NoisyWrenchSensor, w: np.ndarray, t: float) -> np.ndarray:
    context = sensor.CreateDefaultContext()
    sensor.GetInputPort("hand_wrenches_W").FixValue(context, w)
    context.SetTime(t)
    return sensor.GetOutputPort("hand_wrenches_W").Eval(context).copy()


W_TRUE = np.arange(1.0, 13.0)
TORQUES, FORCES = [0, 1, 2, 6, 7, 8], [3, 4, 5, 9, 10, 11]  # rows of [tau_l, f_l, tau_r, f_r]


def _spec_noise(seed: int, k: int, sigma: float) -> np.ndarray:
    """The brief's sample of period k, drawn here independently of the module."""
    return np.random.default_rng([seed, k]).standard_normal(6) * sigma


def test_noise_on_force_rows_only_reproducible_and_held():
    sigma, period = 2.0, 0.01
    sensor = NoisyWrenchSensor(sigma, period, seed=7)
    for k in (0, 1, 123):
        for t in (k * period, (k + 0.5) * period, (k + 1) * period - 1e-6):
            w = _measured(sensor, W_TRUE, t)
            np.testing.assert_array_equal(w[TORQUES], W_TRUE[TORQUES])
            np.testing.assert_allclose(
                w[FORCES] - W_TRUE[FORCES], _spec_noise(7, k, sigma), rtol=1e-12, atol=1e-12
            )
    # Another instance, same seed: the same noise; another seed: different.
    t = 0.4567
    same = _measured(NoisyWrenchSensor(sigma, period, seed=7), W_TRUE, t)
    np.testing.assert_array_equal(same, _measured(sensor, W_TRUE, t))
    other = _measured(NoisyWrenchSensor(sigma, period, seed=8), W_TRUE, t)
    assert np.all(other[FORCES] != same[FORCES])
    # The next period has a new sample; a time on a period boundary within
    # rounding (0.07 / 0.01 = 7.000000000000001, 0.29 / 0.01 = 28.999999999999996)
    # belongs to the period it starts.
    assert not np.array_equal(_measured(sensor, W_TRUE, 0.005), _measured(sensor, W_TRUE, 0.015))
    for t, k in ((0.07, 7), (0.29, 29)):
        np.testing.assert_allclose(
            _measured(sensor, W_TRUE, t)[FORCES] - W_TRUE[FORCES],
            _spec_noise(7, k, sigma),
            atol=1e-12,
        )


def test_noise_statistics():
    """Over 4000 periods (24000 samples): sample std within 3% of sigma
    (its standard error is 0.5%) and mean within 4 standard errors of 0;
    consecutive periods uncorrelated."""
    sigma, period = 1.5, 0.002
    sensor = NoisyWrenchSensor(sigma, period, seed=3)
    context = sensor.CreateDefaultContext()
    sensor.GetInputPort("hand_wrenches_W").FixValue(context, np.zeros(12))
    port = sensor.GetOutputPort("hand_wrenches_W")
    samples = []
    for k in range(4000):
        context.SetTime((k + 0.3) * period)
        samples.append(port.Eval(context)[FORCES].copy())
    x = np.array(samples)
    assert abs(x.std() / sigma - 1.0) < 0.03
    assert abs(x.mean()) < 4 * sigma / np.sqrt(x.size)
    for column in x.T:
        assert abs(np.corrcoef(column[:-1], column[1:])[0, 1]) < 0.1
    assert abs(np.corrcoef(x[:, 0], x[:, 3])[0, 1]) < 0.1  # left vs right hand


def test_noise_is_computed_once_per_time(monkeypatch):
    """The noise is a cache entry on time: new inputs reuse it, a new time
    draws once however often the output is read."""
    calls = []
    real = perturbations.force_noise

    def counting(*args):
        calls.append(args[0])
        return real(*args)

    monkeypatch.setattr(perturbations, "force_noise", counting)
    sensor = NoisyWrenchSensor(1.0, 0.01, seed=0)
    context = sensor.CreateDefaultContext()
    port = sensor.GetOutputPort("hand_wrenches_W")
    sensor.GetInputPort("hand_wrenches_W").FixValue(context, W_TRUE)
    context.SetTime(0.123)
    first = port.Eval(context).copy()
    port.Eval(context)
    assert len(calls) == 1
    sensor.GetInputPort("hand_wrenches_W").FixValue(context, 2 * W_TRUE)
    second = port.Eval(context).copy()
    assert len(calls) == 1
    np.testing.assert_allclose(second - first, W_TRUE)  # same noise, new input
    context.SetTime(0.124)
    port.Eval(context)
    port.Eval(context)
    assert len(calls) == 2


def test_noise_reaches_every_consumer_but_not_the_plant():
    scenario = _scenario(hand_wrench_noise_N=3.0, noise_seed=5)
    scenario.human = HumanConfig(pulls=[PULL])
    built = build_diagram(scenario)
    diagram, plant = built.diagram, built.station.scene.plant
    root = diagram.CreateDefaultContext()
    root.SetTime(1.234)
    true = np.array([0, 0, 0, 0, 0, 0, 0, 0, 0, 7.0, 0, 3.0])
    expected = true.copy()
    expected[FORCES] += _spec_noise(5, 123, 3.0)
    systems = _systems(diagram)
    consumers = ["station/sensing"] + [
        f"standup_controller/{name}" for name in ("state_machine", "controller")
    ]
    for name in consumers:
        system = systems[name]
        got = system.GetInputPort("hand_wrenches_W").Eval(system.GetMyContextFromRoot(root))
        np.testing.assert_allclose(got, expected, atol=1e-12)
    logger = built.logs["hand_wrenches_W"]
    got = logger.get_input_port().Eval(logger.GetMyContextFromRoot(root))
    np.testing.assert_allclose(got, expected, atol=1e-12)
    (applied,) = plant.get_applied_spatial_force_input_port().Eval(plant.GetMyContextFromRoot(root))
    np.testing.assert_array_equal(applied.F_Bq_W.translational(), PULL.force_N)


# --- Mass scale ------------------------------------------------------------------


def test_mass_scale_acts_on_the_simulated_plant_only():
    s = 1.1
    scenario = _scenario(mass_scale=s)
    scenario.human = HumanConfig(pulls=[PULL])
    built = build_diagram(scenario)
    plant, robot = built.station.plant, built.station.robot
    instance = robot.model_instance
    root = built.diagram.CreateDefaultContext()
    root.SetTime(1.0)
    plant_context = plant.GetMyMutableContextFromRoot(root)
    set_seated_state(built.station.scene, plant_context)
    nominal_context = plant.CreateDefaultContext()
    nominal = plant.CalcTotalMass(nominal_context, [instance])
    apply_model_errors(built.station.scene, plant_context, scenario)
    apply_model_errors(built.station.scene, plant_context, scenario)  # idempotent
    assert plant.CalcTotalMass(plant_context, [instance]) == pytest.approx(s * nominal, rel=1e-12)
    for index in plant.GetBodyIndices(instance):
        body = plant.get_body(index)
        M0 = body.CalcSpatialInertiaInBodyFrame(nominal_context)
        M1 = body.CalcSpatialInertiaInBodyFrame(plant_context)
        assert M1.get_mass() == pytest.approx(s * M0.get_mass(), rel=1e-12)
        np.testing.assert_allclose(M1.get_com(), M0.get_com(), atol=1e-15)
        np.testing.assert_allclose(
            M1.CalcRotationalInertia().CopyToFullMatrix3(),
            s * M0.CalcRotationalInertia().CopyToFullMatrix3(),
            rtol=1e-12,
            atol=1e-15,
        )
    # The simulated mass matrix (at the default pose) scales as a whole.
    x = plant.GetPositionsAndVelocities(plant_context)
    plant.SetPositionsAndVelocities(nominal_context, x)
    M_nominal = plant.CalcMassMatrix(nominal_context)
    np.testing.assert_allclose(plant.CalcMassMatrix(plant_context), s * M_nominal, rtol=1e-12)

    # The controller's terms, at the simulated state, use the nominal model.
    model = _systems(built.diagram)["standup_controller/controller"].model
    terms = model.kinematics.calc(x, ["l_sole"])
    assert terms.mass_kg == pytest.approx(nominal, rel=1e-12)
    np.testing.assert_allclose(terms.M, M_nominal, rtol=1e-12, atol=1e-12)
    # Sensing: Omega f of a pure force is that force over the nominal mass.
    sensing = _systems(built.diagram)["station/sensing"]
    omega_f = sensing.GetOutputPort("omega_f_W").Eval(sensing.GetMyContextFromRoot(root))
    np.testing.assert_allclose(omega_f, np.array(PULL.force_N) / nominal, rtol=1e-9)


def test_simulate_applies_the_mass_scale_and_reports_both_masses():
    """A 20 ms run: simulate() scales the simulated robot; metrics keep the
    model's mass and add the simulated one, whose weight the contacts carry."""
    scenario = _scenario(mass_scale=1.05)
    scenario.duration_s = 0.02
    metrics = simulate(scenario, None, record=False, progress=False).metrics
    nominal = Scenario()
    built = build_diagram(nominal)
    instance = built.station.scene.robot.model_instance
    mass = built.station.scene.plant.CalcTotalMass(
        built.station.scene.plant.CreateDefaultContext(), [instance]
    )
    assert metrics["robot_mass_kg"] == pytest.approx(mass, rel=1e-12)
    assert metrics["simulated_mass_kg"] == pytest.approx(1.05 * mass, rel=1e-12)
    assert metrics["weight_N"] == pytest.approx(1.05 * mass * 9.81, rel=1e-12)


# --- Friction scale --------------------------------------------------------------


def _proximity(inspector) -> dict[str, object]:
    """Geometry name -> proximity properties (GeometryIds differ between scenes)."""
    return {
        inspector.GetName(gid): inspector.GetProximityProperties(gid)
        for gid in inspector.GetAllGeometryIds(Role.kProximity)
    }


def _candidates(inspector) -> set[tuple[str, str]]:
    """The pairs of geometry names the collision filters leave to test."""
    return {
        tuple(sorted(map(inspector.GetName, pair))) for pair in inspector.GetCollisionCandidates()
    }


def _friction(props) -> tuple[float, float]:
    mu = props.GetProperty("material", "coulomb_friction")
    return mu.static_friction(), mu.dynamic_friction()


# The number-valued proximity properties besides friction (the hydroelastic
# compliance type has no Python binding to read it by).
NUMERIC_PROPERTIES = [
    ("material", "hunt_crossley_dissipation"),
    ("hydroelastic", "hydroelastic_modulus"),
    ("hydroelastic", "resolution_hint"),
    ("hydroelastic", "slab_thickness"),
]


def test_friction_scale_scales_every_surface_and_keeps_the_rest():
    """Each proximity geometry (robot pads, floor, chair) gets s times its
    friction; every other property and the collision filters stay."""
    s = 0.8
    scaled = build_diagram(_scenario(friction_scale=s)).station.scene.scene_graph.model_inspector()
    nominal = build_diagram(Scenario()).station.scene.scene_graph.model_inspector()
    props, ref = _proximity(scaled), _proximity(nominal)
    assert set(props) == set(ref)
    assert {"floor::floor_collision", "chair::seat_collision", "iCub::l_sole_pad"} <= set(props)
    assert len(props) == 7
    for name, p in props.items():
        assert _friction(ref[name]) == (1.0, 1.0)  # the files' values
        assert _friction(p) == pytest.approx((s, s), rel=1e-15), name
        for group in ref[name].GetGroupNames():
            keys = set(ref[name].GetPropertiesInGroup(group))
            assert set(p.GetPropertiesInGroup(group)) == keys
        for group, key in NUMERIC_PROPERTIES:
            if ref[name].HasProperty(group, key):
                assert p.GetProperty(group, key) == ref[name].GetProperty(group, key)
    assert _candidates(scaled) == _candidates(nominal)
    assert ("chair::seat_collision", "iCub::buttocks_pad") in _candidates(scaled)
    # Drake's pair rule 2 mu1 mu2 / (mu1 + mu2) on two scaled surfaces: s mu.
    pair = CalcContactFrictionFromSurfaceProperties(CoulombFriction(s, s), CoulombFriction(s, s))
    assert pair.dynamic_friction() == pytest.approx(s)


BLOCK_SDF = """<?xml version="1.0"?>
<sdf version="1.9" xmlns:drake="http://drake.mit.edu">
  <model name="block">
    <link name="block">
      <inertial><mass>1.0</mass>
        <inertia><ixx>0.004</ixx><iyy>0.004</iyy><izz>0.007</izz></inertia>
      </inertial>
      {spheres}
    </link>
  </model>
</sdf>
"""
SPHERE = """<collision name="c{i}"><pose>{x} {y} -0.04 0 0 0</pose>
        <geometry><sphere><radius>0.01</radius></sphere></geometry>
        <drake:proximity_properties>
          <drake:mu_static>0.5</drake:mu_static><drake:mu_dynamic>0.5</drake:mu_dynamic>
        </drake:proximity_properties></collision>"""


def _sliding_speed(scale: float, push_N: float, t_end: float = 0.3) -> float:
    """A 1 kg block on four point-contact spheres (mu 0.5) on the scene's
    floor (mu 1.0), pushed horizontally at its CoM from rest: its speed at t_end."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(
        MultibodyPlantConfig(time_step=1e-3, discrete_contact_approximation="similar"), builder
    )
    spheres = "\n".join(
        SPHERE.format(i=i, x=x, y=y)
        for i, (x, y) in enumerate([(0.05, 0.05), (0.05, -0.05), (-0.05, 0.05), (-0.05, -0.05)])
    )
    parser = Parser(plant)
    (floor,) = parser.AddModels(str(model_file("floor.sdf")))
    parser.AddModelsFromString(BLOCK_SDF.format(spheres=spheres), "sdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("floor", floor))
    plant.Finalize()
    scale_friction(plant, scene_graph, scale)
    block = plant.GetBodyByName("block")
    force = ExternallyAppliedSpatialForce()
    force.body_index = block.index()
    force.p_BoBq_B = np.zeros(3)
    force.F_Bq_W = SpatialForce(np.zeros(3), [push_N, 0.0, 0.0])
    source = builder.AddSystem(
        ConstantValueSource(Value[list[ExternallyAppliedSpatialForce]]([force]))
    )
    builder.Connect(source.get_output_port(), plant.get_applied_spatial_force_input_port())
    simulator = Simulator(builder.Build())
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    # Resting on its spheres, with the point contact's static penetration.
    plant.SetFreeBodyPose(context, block, RigidTransform([0, 0, 0.0499]))
    simulator.AdvanceTo(t_end)
    return float(block.EvalSpatialVelocityInWorld(context).translational()[0])


def test_plant_slides_with_the_scaled_friction():
    """Independent physics: the block's pair coefficient is 2 (0.5 s)(1 s) /
    (0.5 s + 1 s) = (2/3) s. Pushed with 0.5 m g it sticks at s = 1 and slides
    at s = 0.3 (mu = 0.2) with acceleration (0.5 - 0.2) g."""
    g, push = 9.81, 0.5 * 9.81
    assert abs(_sliding_speed(1.0, push)) < 1e-3
    t_end = 0.3
    a = _sliding_speed(0.3, push, t_end) / t_end
    assert a == pytest.approx((0.5 - 0.2) * g, rel=0.05)
