"""The whole-body controller's parts, each one idea (dairlib OSC style).

    terms.py       the robot's kinematic and dynamic terms at one state (M, h, J, Jdot v, CoM)
    contacts.py    contact wrenches: friction pyramid, CoP box, normal-force bounds, maps;
                   the controller's contact set (CONTACTS) and what a plan asks of it
                   (ContactCommands, made by standup/contact_schedule.py)
    mass.py        the mass estimate: the robot weighs itself seated (MassEstimator)
    model.py       the controller's model: its contacts and joints, the terms once a tick
                   (ControllerModel)
    targets.py     what the tasks track: one mode's settings and one tick's references
                   (TaskReferences, made by standup/task_references.py)
    tasks/         Task objects, a module each: centroidal momentum (momentum.py), CoP
                   centering (cop.py), posture (posture.py), base orientation (base.py),
                   the soles' moment rate (moment_rate.py), the joint limits' and the
                   shoulders' tendon bounds (joint_limits.py); each with its weight,
                   active modes and update()
    qp_types.py    the QP's types: the unknowns' layout, the contact map, the task and
                   bound protocols, the contact plan's bounds, the solution
    qp.py          the one QP over [contact wrenches, vdot], which consumes any list of
                   tasks (WholeBodyQp); soft_rows.py its soft joint-limit rows;
                   pad_dynamics.py a seat pad's normal-dynamics row; backends.py the
                   solvers (daqp, Drake's OSQP and Clarabel)
    controller.py  WholeBodyController, a plain object: terms + task references + contact
                   commands -> torques; adding a task is adding an object to its list
                   (make_program), not editing the QP
    smooth.py      the C1 blend the laws fade with

standup/whole_body.py calls them once a tick, as one system beside the state machine, the
advancement and the CoM reference (standup/standup_controller.py).
"""
