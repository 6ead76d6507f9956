"""The simulated kitchen-storage world (PyBullet, DIRECT mode), built from parts."""
