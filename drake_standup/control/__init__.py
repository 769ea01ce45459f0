"""The whole-body controller's parts, each one idea (dairlib OSC style).

    terms.py       the robot's kinematic and dynamic terms at one state (M, h, J, Jdot v, CoM)
    contacts.py    contact wrenches: friction pyramid, CoP box, normal-force bounds, maps
    schedule.py    the contact schedule: from the stand-up mode, the contacts' bounds and
                   the seat's hold (ContactScheduler)
    mass.py        the mass estimate: the robot weighs itself seated (MassEstimator)
    model.py       the controller's model: its contacts and joints, the terms once a tick
                   (ControllerModel)
    references.py  what the tasks track: the phase table's gains, postures and base pitch,
                   and each tick's references (Ldot*, f_par, q_ref; TaskReferenceGenerator)
    tasks.py       Task objects (centroidal momentum, CoP centering, posture, base
                   orientation), each with its weight, active states and update(), and
                   the joint-limit acceleration bounds
    qp.py          the one QP over [contact wrenches, vdot], which consumes any list of
                   tasks, and its solver backends
    controller.py  WholeBodyController, the thin LeafSystem: terms + task references +
                   contact commands -> torques; adding a task is adding an object to its
                   list (make_program), not editing the QP

drake_standup/standup/standup_controller.py wires them with the state machine, the advancement
and the CoM reference into the stand-up controller's diagram.
"""
