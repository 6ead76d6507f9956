"""Agents: what decides the next primitive and its parameters from an observation."""
