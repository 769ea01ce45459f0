"""The helper: whoever holds the robot's hands, and what helping costs them.

One word for each kind (human.mode in a scenario):
- scripted: pulls set in advance, each a trapezoid in time (hands.py, scripted_forces);
- reactive: a partner who guides each hand from what they saw of the robot, late, through
  an arm's impedance (partner.py: the velocity and the path guide);
- body: a person's body kneeling in front of the robot, with their own joints, strength
  and grips (anthropometry.py: the body from de Leva's table; body.py: that body in the
  plant, placed, its strength and impedance; body_control.py: the person's controller
  and the grips);
- recorded: a person's hand wrenches replayed from a CSV file (recorded.py; the file's
  format: docs/helpers.md).

Which module holds what, and the ports the diagram (sim/diagram.py) reads:
    hands.py          HumanWrenchSource (scripted, reactive): robot_state in;
                      hand_wrenches_W (12) and spatial_forces out, to the station's hands
    partner.py        the reactive partner's forces, evaluated by HumanWrenchSource
    anthropometry.py  the person's segments scaled to a height and mass, add_person
    body.py           HelperBody: the person in the plant, placement, strength, grip frames
    body_control.py   make_body_helper: the person's controller and the Grips, with
                      HumanWrenchSource's ports (the robot feels the grips)
    recorded.py       make_recorded_helper: RecordedWrenchSource (recorded), the
                      recording interpolated in time, HumanWrenchSource's ports
    work.py           HelperWork: work, impulse and peak force over the plant's steps
                      (helper_spent, 4)

The layer sits on config, ports and robot; world/ (the scene and the station) places the
person's body and senses the hands, and nothing here reads the world back.
"""
