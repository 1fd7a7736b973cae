"""NEAT settings files: values neat-python would accept and fail on later, or silently
ignore, are refused at load with one line naming the file, section and key."""

import re

import pytest

from evorbc_ros.config import ConfigError, config_dir
from offline_evolution.arbitrator.neat_config import load_neat_config

SHIPPED = (config_dir() / "neat" / "4ws.ini").read_text()


def with_setting(key, value):
    """The shipped file with ``key`` set to ``value`` (added to [NEAT] if absent)."""
    text, n = re.subn(rf"^{key}\s*=.*$", f"{key} = {value}", SHIPPED, flags=re.M)
    return text if n else text.replace("[NEAT]\n", f"[NEAT]\n{key} = {value}\n")


@pytest.mark.parametrize(
    ("key", "value", "needle"),
    [
        ("conn_add_prob", "2.5", "[EvoRBCGenome] conn_add_prob is a probability"),
        ("weight_mutate_power", "nan", "[EvoRBCGenome] weight_mutate_power must be a finite"),
        ("bias_max_value", "-20", "bias_min_value (-10.0) is above bias_max_value (-20.0)"),
        ("initial_connection", "bogus", "initial_connection must be one of"),
        ("compatibility_threshold", "-1", "compatibility_threshold must be > 0"),
        ("elitism", "500", "elitism must be in [0, pop_size)"),
        ("target_species_count", "0", "target_species_count must be >= 1"),
        ("pop_size", "6", "pop_size must hold target_species_count x min_species_size"),
        ("pop_size", "1", "pop_size must be at least 2"),
        ("species_fitness_func", "foo", "species_fitness_func"),
        ("max_stagnation", "abc", "max_stagnation"),
    ],
)
def test_bad_values_are_refused_naming_the_key(tmp_path, key, value, needle):
    path = tmp_path / "bad.ini"
    path.write_text(with_setting(key, value))
    with pytest.raises(ConfigError) as info:
        load_neat_config(path, 6, 2)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and needle in message and "\n" not in message


def test_an_unknown_key_outside_neat_is_refused(tmp_path):
    path = tmp_path / "typo.ini"
    path.write_text(
        SHIPPED.replace("[DefaultReproduction]\n", "[DefaultReproduction]\nelitsm = 2\n")
    )
    with pytest.raises(ConfigError, match="elitsm"):
        load_neat_config(path, 6, 2)


def test_the_shipped_files_pass():
    for family in ("4ws", "hexapod"):
        assert load_neat_config(config_dir() / "neat" / f"{family}.ini", 6, 2).pop_size == 150
