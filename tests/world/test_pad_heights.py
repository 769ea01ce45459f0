"""RobotSensing's pad heights (thigh_z_W, buttocks_z_W: how near the seat the sit-down's
pads are) against the pads' collision boxes as the scene graph holds them."""

from __future__ import annotations

import numpy as np
from pydrake.geometry import Box, Role
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drake_standup.robot.icub import add_icub
from drake_standup.world.sensing import RobotSensing, buttocks_points, thigh_points


def test_the_pad_heights_are_the_lowest_bottom_face_centres_of_their_boxes():
    """At random poses each output is the lower world z of the centres of its pads' boxes'
    bottom faces, from the collision geometry registered in the scene graph (its pose in
    the body, its box size) and Drake's body poses."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    robot = add_icub(plant, visuals=False)
    plant.Finalize()
    diagram = builder.Build()
    sensing = RobotSensing(
        plant, robot, {}, thigh_points(robot), buttocks_points=buttocks_points(robot)
    )
    context = sensing.CreateDefaultContext()
    root = diagram.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(root)
    inspector = scene_graph.model_inspector()
    groups = {"thigh": [], "buttocks": []}
    for shape in robot.contact_shapes:
        if shape.group in groups:
            groups[shape.group].append(shape.name)
    assert len(groups["thigh"]) == 2 and len(groups["buttocks"]) == 1
    ids = {
        inspector.GetName(g).split("::")[-1]: g
        for g in inspector.GetAllGeometryIds(Role.kProximity)
    }
    rng = np.random.default_rng(5)
    nq = plant.num_positions()
    for _ in range(4):
        q = plant.GetDefaultPositions()
        q[:4] = rng.normal(size=4)
        q[:4] /= np.linalg.norm(q[:4])
        q[4:7] = rng.normal(scale=0.3, size=3)
        q[7:] += rng.uniform(-0.5, 0.5, nq - 7)
        x = np.concatenate([q, np.zeros(plant.num_velocities())])
        plant.SetPositionsAndVelocities(plant_context, x)
        sensing.GetInputPort("robot_state").FixValue(context, x)
        for port, group in (("thigh_z_W", "thigh"), ("buttocks_z_W", "buttocks")):
            zs = []
            for name in groups[group]:
                geometry = ids[name]
                box = inspector.GetShape(geometry)
                assert isinstance(box, Box)
                body = plant.GetBodyFromFrameId(inspector.GetFrameId(geometry))
                X_WG = plant.EvalBodyPoseInWorld(plant_context, body) @ inspector.GetPoseInFrame(
                    geometry
                )
                zs.append((X_WG @ np.array([0.0, 0.0, -box.height() / 2]))[2])
            z = sensing.GetOutputPort(port).Eval(context)[0]
            np.testing.assert_allclose(z, min(zs), atol=1e-12)
