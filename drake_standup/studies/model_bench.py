"""What the controller's model costs a tick, by library (issue 48; a benchmark, not a test).

    python -m drake_standup.studies.model_bench [--robot NAME] [--calls N] [--rounds K]

On random states near the seated pose of the robot, each library computes the terms the
controller's tick asks for (control/terms.py RobotTerms): while seated (the seat, both
thighs and both soles, no hand), and under a pull (the same and both hands). The
libraries run round by round in turn, so the machine's load falls on both alike; one JSON
summary goes to stdout: the median of the rounds' mean microseconds per call, and the
ratio of each library to Drake's. Also timed: the bare library calls of one pass (what
the Python around them adds is the rest).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import statistics
import time
from functools import partial

import numpy as np
import pinocchio as pin
from pydrake.systems.framework import DiagramBuilder

from drake_standup.config import Scenario
from drake_standup.control.model import HANDS, contact_specs
from drake_standup.control.pinocchio_terms import PinocchioKinematics
from drake_standup.control.terms import RobotKinematics
from drake_standup.world.scene import add_scene, set_seated_state


def _states(plant, x0: np.ndarray, count: int, rng) -> list[np.ndarray]:
    nq = plant.num_positions()
    states = []
    for _ in range(count):
        x = x0.copy()
        x[7:nq] += rng.uniform(-0.2, 0.2, nq - 7)
        x[nq:] = rng.normal(scale=0.3, size=plant.num_velocities())
        states.append(x)
    return states


def _calc(kinematics, names, world, x):
    return kinematics.calc(x, names, world)


def _per_call_us(function, states: list[np.ndarray]) -> float:
    start = time.perf_counter()
    for x in states:
        function(x)
    return (time.perf_counter() - start) / len(states) * 1e6


def measure(robot_model: str, calls: int, rounds: int) -> dict:
    """The summary of the module docstring."""
    base = Scenario()
    scenario = dataclasses.replace(base, robot=dataclasses.replace(base.robot, model=robot_model))
    scene = add_scene(DiagramBuilder(), scenario, visuals=False)
    plant, robot = scene.plant, scene.robot
    specs = contact_specs(plant, robot, scenario.controller, scenario.chair)
    frames = {
        "held_frames": [s.frame for s in specs if s.constrained],
        "other_frames": [s.frame for s in specs if not s.constrained] + list(HANDS),
        "hold_points_m": {s.frame: s.hold_point_m for s in specs},
    }
    libraries = {
        "drake": RobotKinematics(plant, robot, **frames),
        "pinocchio": PinocchioKinematics(plant, robot, **frames),
    }
    context = plant.CreateDefaultContext()
    set_seated_state(scene, context)
    states = _states(
        plant, plant.GetPositionsAndVelocities(context), calls, np.random.default_rng(0)
    )
    contacts = [s.frame for s in specs]
    requests = {"seated": (contacts, ()), "pulled": (contacts, list(HANDS))}
    dynamics = libraries["pinocchio"].dynamics
    tree, data = dynamics.tree, dynamics._data()

    def drake_calls(x):
        plant.SetPositionsAndVelocities(context, x)
        plant.CalcMassMatrix(context)
        plant.CalcBiasTerm(context)

    def pinocchio_calls(x):
        q_pin = x.take(tree.q_take)
        q_pin[3:7] /= np.linalg.norm(q_pin[3:7])
        v_pin = x[plant.num_positions() :].take(tree.v_drake)
        pin.crba(tree.model, data, q_pin, pin.Convention.WORLD)
        pin.rnea(tree.model, data, q_pin, v_pin, v_pin)
        pin.forwardKinematics(tree.model, data, q_pin, v_pin, v_pin)

    samples: dict[str, list[float]] = {}
    for _ in range(rounds):
        for request, (names, world) in requests.items():
            for library, kinematics in libraries.items():
                key = f"{library} {request}"
                samples.setdefault(key, []).append(
                    _per_call_us(partial(_calc, kinematics, names, world), states)
                )
        samples.setdefault("drake mass matrix and bias calls", []).append(
            _per_call_us(drake_calls, states)
        )
        samples.setdefault("pinocchio crba, rnea, forward kinematics calls", []).append(
            _per_call_us(pinocchio_calls, states)
        )
    medians = {key: statistics.median(values) for key, values in samples.items()}
    ratios = {
        f"pinocchio / drake, {request}": medians[f"pinocchio {request}"]
        / medians[f"drake {request}"]
        for request in requests
    }
    return {
        "robot": robot_model,
        "calls_per_round": calls,
        "rounds": rounds,
        "us_per_call_median_of_rounds": medians,
        "ratios": ratios,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", default=Scenario().robot.model)
    parser.add_argument("--calls", type=int, default=500, help="states per round")
    parser.add_argument("--rounds", type=int, default=7)
    args = parser.parse_args(argv)
    print(json.dumps(measure(args.robot, args.calls, args.rounds), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
