"""NEAT settings that neat-python accepts and then misbehaves on (negative spreads and
counts, a NaN threshold, unknown criteria and init types) are refused at load, in one line
naming the file, section and key."""

import pytest
from test_neat_config_errors import with_setting

from evorbc_ros.config import ConfigError
from offline_evolution.arbitrator.neat_config import load_neat_config


@pytest.mark.parametrize(
    ("key", "value", "needle"),
    [
        ("max_stagnation", "-1", "[DefaultStagnation] max_stagnation must be >= 0, got -1"),
        ("max_stagnation", "0", "[DefaultStagnation] max_stagnation must be >= 1"),
        ("species_elitism", "-2", "[DefaultStagnation] species_elitism must be >= 0, got -2"),
        ("weight_mutate_power", "-0.5", "[EvoRBCGenome] weight_mutate_power must be >= 0"),
        ("bias_init_stdev", "-1", "[EvoRBCGenome] bias_init_stdev must be >= 0, got -1"),
        ("num_hidden", "-1", "[EvoRBCGenome] num_hidden must be >= 0, got -1"),
        (
            "compatibility_weight_coefficient",
            "-0.5",
            "[EvoRBCGenome] compatibility_weight_coefficient must be >= 0, got -0.5",
        ),
        ("compatibility_disjoint_coefficient", "-1", "compatibility_disjoint_coefficient must"),
        ("weight_init_stdev", "-3", "[EvoRBCGenome] weight_init_stdev must be >= 0"),
        ("fitness_threshold", "nan", "[NEAT] fitness_threshold must be a finite number, got nan"),
        ("fitness_criterion", "best", "[NEAT] fitness_criterion must be one of max, min, mean"),
        ("bias_init_type", "bogus", "[EvoRBCGenome] bias_init_type must be one of gaussian"),
        ("weight_init_type", "uniformly", "weight_init_type must be one of gaussian"),
    ],
)
def test_settings_neat_python_misbehaves_on_are_refused(tmp_path, key, value, needle):
    path = tmp_path / "bad.ini"
    path.write_text(with_setting(key, value))
    with pytest.raises(ConfigError) as info:
        load_neat_config(path, 10, 2)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and needle in message and "\n" not in message


def test_the_bogus_init_type_is_refused_by_the_cli_before_evolving(tmp_path, capsys,
                                                                    small_repertoire):  # fmt: skip
    from offline_evolution.cli import main

    rep, neat = tmp_path / "r.json", tmp_path / "n.ini"
    small_repertoire.save(rep)
    neat.write_text(with_setting("bias_init_type", "bogus"))
    code = main(["arbitrator", "--repertoire", str(rep), "--neat-config", str(neat),
                 "--out", str(tmp_path / "a.json")])  # fmt: skip
    err = capsys.readouterr().err.strip()
    assert code == 1 and "internal error" not in err and len(err.splitlines()) == 1
    assert err.startswith(f"evorbc-evolve: error: {neat}: [EvoRBCGenome] bias_init_type")
