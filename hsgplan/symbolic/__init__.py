"""The symbolic world: the hand-written rules (transition model, PDDL domain) and the random
goals and start states. They serve the symbolic loop, goal validation, demonstrations and the
search baseline; the agents' decision path does not consult them."""
