"""f_p: object poses from camera images (DOPE-style keypoints, PnP, several views)."""
