"""The robot's own senses and muscles (robot.hardware: icub), between world/ and control/.

hardware.py    the iCub's numbers, each cited: rate, encoders, IMU, F/T sensors,
               joint friction, the torque loop, the motors' limits
sensors.py     RobotSensors: what the sensors read of the plant (encoders, the waist
               IMU, the six F/T sensors), with their resolution, noise and offsets
subtrees.py    the robot cut at its F/T sensors: each piece's external wrench
               from the sensors and its own dynamics (wholeBodyDynamics' idea)
estimator.py   RobotEstimator: the robot's state, hands' wrenches and pads' loads
               from the sensors alone (legged odometry with the IMU's attitude)
muscles.py     JointMuscles: the torque loop's lag, the motors' limits, the joints'
               friction and the firmware's compensation of it
wiring.py      add_senses / add_muscles: the systems in a diagram, and the ports
               the stand-up controller reads under icub (the station's names)
"""
