"""The gait design search of a legged robot (``evorbc-evolve design-gait``, docs/legged.md)."""
