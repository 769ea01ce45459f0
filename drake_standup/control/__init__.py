"""The whole-body controller's parts, each one idea (dairlib OSC style).

    terms.py       the robot's kinematic and dynamic terms at one state (M, h, J, Jdot v, CoM)
    contacts.py    contact wrenches: friction pyramid, CoP box, normal-force bounds, maps
    references.py  what the tasks track: the per-state schedule (CoM gains, posture table,
                   base pitch, seat hinge) and each tick's references (Ldot*, f_par, q_ref)
    tasks.py       Task objects (centroidal momentum, CoP centering, posture, base
                   orientation), each with its weight, active states and update(), and
                   the joint-limit acceleration bounds
    qp.py          the one QP over [contact wrenches, vdot], which consumes any list of
                   tasks, and its solver backends

drake_standup/controller.py wires them into the WholeBodyController LeafSystem: ports,
discrete state, the contact plan's programs; adding a task is adding an object to its
list (WholeBodyController._program), not editing the QP.
"""
