"""The simulated world: the scene (chair, floor), the station (plant, pad forces,
sensing, perturbations) and the human's wrench on the hands."""
