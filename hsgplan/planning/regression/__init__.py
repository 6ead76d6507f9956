"""The learned regression task planner: encodings, networks, the regression loop."""
