"""The simulated world: the scene (chair, floor, where the robot and a person's body sit),
the seating, the station (plant, pad forces, sensing, perturbations). The helper who
pulls the hands is a layer of its own, below (drake_standup/helper/)."""
