"""Independent references for our engines: pybullet_reference (pybullet with its own loaders) and
cross_validation (every engine against it and against the closed form)."""
