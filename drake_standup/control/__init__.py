"""The whole-body controller's parts, each one idea (dairlib OSC style).

    terms.py     the robot's kinematic and dynamic terms at one state (M, h, J, Jdot v, CoM)
    contacts.py  contact wrenches: friction pyramid, CoP box, normal-force bounds, maps
    tasks.py     least-squares tasks: centroidal momentum (with the human's help), posture
    qp.py        the one QP over [contact wrenches, vdot] and its solver backends

drake_standup/controller.py wires them into the WholeBodyController LeafSystem.
"""
