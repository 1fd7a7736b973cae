"""Shared fixtures."""

import pytest

from offline_evolution.repertoire.map_elites import generate_repertoire
from offline_evolution.repertoire.settings import load_settings


def small_settings(**overrides):
    """A quick 4WS MAP-Elites run: Table I settings with a small budget."""
    values = {
        "robot": "4ws-5",
        "initial_batch": 400,
        "batch_size": 100,
        "iterations": 25,
        "seed": 7,
    }
    values.update(overrides)
    return load_settings(**values)


@pytest.fixture(scope="session")
def small_repertoire():
    """A small 4ws-5 repertoire, generated once per test session."""
    return generate_repertoire(small_settings())
