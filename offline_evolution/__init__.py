"""Offline evolution for EvoRBC: MAP-Elites repertoires, NEAT arbitrators, tasks and plots."""
