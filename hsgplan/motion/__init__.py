"""Motion generation ψ: motion parameters (bins) for a subgoal from the grounded scene graph."""
