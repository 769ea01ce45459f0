"""The diagram: the station, the stand-up controller and the human, wired by port name;
its export shows every system inside its box."""

from __future__ import annotations

import pytest
from pydrake.systems.framework import Diagram, InputPortIndex

from drake_standup.config import load_scenario
from drake_standup.sim.diagram import build_diagram

STATION = ("plant", "scene_graph", "contact_forces", "sensing", "hand_wrench_sensor")
# The systems of the paper; the schedule, the model and the task references are plain
# objects inside the controller's tick (standup/whole_body.py).
CONTROLLER = ("state_machine", "advancement", "com_reference", "controller")


@pytest.fixture(scope="module")
def built():
    return build_diagram(load_scenario())


def test_the_station_and_the_controller_hold_their_systems(built):
    root = built.diagram
    systems = {s.get_name(): s for s in root.GetSystems()}
    assert {"station", "human", "standup_controller"} <= set(systems)
    for box, names in (("station", STATION), ("standup_controller", CONTROLLER)):
        inside = {s.get_name() for s in systems[box].GetSystems()}
        assert set(names) <= inside, (box, set(names) - inside)


def test_signals_flow_from_the_human_through_the_station_to_the_controller(built):
    """Resolved through the diagrams' exported ports down to leaf systems: the pull
    reaches the plant, the measured wrenches reach the state machine, the controller's
    torques reach the plant, the station's sensors feed the state machine and the
    advancement."""
    root = built.diagram
    systems = {s.get_name(): s for s in root.GetSystems()}
    station, brain = systems["station"], systems["standup_controller"]

    def source_of(box, leaf_name, port_name):
        leaf = box.GetSubsystemByName(leaf_name)
        index = leaf.GetInputPort(port_name).get_index()
        source, output = box.connection_map().get((leaf, index), (None, None))
        if source is None:  # an exported input of box: follow it out into root
            exported = next(
                i
                for i in range(box.num_input_ports())
                if (leaf, index) in box.GetInputPortLocators(InputPortIndex(i))
            )
            source, output = root.connection_map()[(box, InputPortIndex(exported))]
        while isinstance(source, Diagram):
            source, output = source.get_output_port_locator(output)
        return source.get_name(), source.get_output_port(output).get_name()

    assert source_of(station, "plant", "applied_spatial_force") == ("human", "spatial_forces")
    assert source_of(station, "hand_wrench_sensor", "u") == ("human", "hand_wrenches_W")
    assert source_of(brain, "state_machine", "hand_wrenches_W") == ("hand_wrench_sensor", "y")
    assert source_of(brain, "state_machine", "pad_forces_W") == ("contact_forces", "pad_forces_W")
    assert source_of(brain, "advancement", "com_W") == ("sensing", "com_W")
    assert source_of(brain, "com_reference", "psi") == ("advancement", "psi")
    assert source_of(brain, "com_reference", "segment") == ("state_machine", "segment")
    assert source_of(brain, "com_reference", "com_W") == ("sensing", "com_W")
    assert source_of(brain, "controller", "mode") == ("state_machine", "mode")
    assert source_of(brain, "controller", "com_reference") == ("com_reference", "com_reference")
    assert source_of(brain, "controller", "robot_state") == ("plant", "iCub_state")
    assert source_of(station, "plant", "iCub_actuation") == ("controller", "actuation")


def test_dot_shows_every_system_in_its_box(built, tmp_path):
    from drake_standup.outputs.recording import export_diagram

    dot = export_diagram(built.diagram, tmp_path)[0].read_text()
    for name in ("station", "standup_controller", "human", *STATION, *CONTROLLER):
        assert f"name={name}" in dot, name


@pytest.mark.parametrize("library", ["drake", "pinocchio"])
def test_the_sensed_com_reads_the_controllers_com_of_the_same_state(library):
    """Issue 48, with either model library: the sensing reads the CoM the controller's
    tick computed for the same state (robot/last_com.py) instead of computing it again;
    its reads are those of the sensing's own CoM output, and the values are Drake's CoM
    of that state to round-off."""
    import dataclasses

    from pydrake.systems.analysis import Simulator

    from drake_standup.world.scene import robot_last_com

    base = load_scenario()
    controller = dataclasses.replace(base.controller, model_library=library)
    built = build_diagram(dataclasses.replace(base, controller=controller))
    last_com = robot_last_com(built.station.scene)
    systems = {s.get_name(): s for s in built.diagram.GetSystems()}
    sensing = systems["station"].GetSubsystemByName("sensing")
    controller = systems["standup_controller"].GetSubsystemByName("controller")
    assert sensing._last_com is last_com
    assert controller.model.kinematics.last_com is last_com
    simulator = Simulator(built.diagram)
    simulator.Initialize()
    simulator.AdvanceTo(1.0)
    last_com.hits = 0
    simulator.AdvanceTo(1.4)
    assert last_com.hits >= 20
    context = simulator.get_context()
    station_context = systems["station"].GetMyContextFromRoot(context)
    plant = built.station.scene.plant
    plant_context = plant.GetMyContextFromRoot(context)
    com = systems["station"].GetOutputPort("com_W").Eval(station_context)
    drake_com = plant.CalcCenterOfMassPositionInWorld(
        plant_context, [built.station.robot.model_instance]
    )
    assert abs(com - drake_com).max() < 1e-12
