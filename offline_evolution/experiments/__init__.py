"""Scripted experiments that reproduce the paper's comparisons (results go to ``docs/``)."""
