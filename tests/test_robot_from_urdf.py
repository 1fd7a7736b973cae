"""``evorbc-evolve robot-from-urdf``: a legged robot's settings read from its URDF alone
(docs/legged.md, "From a URDF").

The A1's derived settings are checked against the shipped, hand-made ones; the Laikago's
(pybullet_data's Z-up file) register on ``$EVORBC_ROBOT_PATH`` and stand; a Y-up copy of
the A1 is read back to the A1's values; unusable URDFs are refused in one line.
"""

import math
from pathlib import Path

import numpy as np
import pybullet_data
import pytest

from evorbc_ros.config import config_dir
from evorbc_ros.robots import registry
from evorbc_ros.robots.settings_robots import PATH_VARIABLE
from offline_evolution.cli import main
from sim_bridge.legged.settings import load_robot_settings
from sim_bridge.legged.urdf_check import stand_check
from sim_bridge.legged.urdf_model import read_urdf, turned_urdf_text
from sim_bridge.robots import make_robot

DATA = Path(pybullet_data.getDataPath())


def run(capsys, *argv) -> tuple[int, str, str]:
    code = main(["robot-from-urdf", *argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def a1_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("a1")
    assert main(["robot-from-urdf", "pybullet_data:a1/a1.urdf", "--out", str(folder)]) == 0
    return folder


def test_the_a1_read_from_its_urdf_is_the_shipped_a1(a1_files):
    """Links, joints, mirrors, couplings and frequency equal the hand-made settings; the
    knee's standing range is within 0.5 deg (the shipped one is rounded to whole degrees)."""
    got = load_robot_settings(a1_files / "a1_description-model.yaml")
    want = load_robot_settings(config_dir() / "robots" / "a1.yaml")
    assert (got.base_link, got.foot_links) == (want.base_link, want.foot_links)
    assert got.gait.joint_names == want.gait.joint_names
    assert got.gait.frequency == want.gait.frequency == 2.5
    assert got.footprint_radius == want.footprint_radius == 0.40
    for g, w in zip(got.gait.oscillators, want.gait.oscillators, strict=True):
        assert (g.name, g.mirror, g.mirror_sign) == (w.name, w.mirror, w.mirror_sign)
        assert abs(g.low - w.low) < math.radians(0.5) and abs(g.high - w.high) < math.radians(0.5)
    for g, w in zip(got.gait.joints, want.gait.joints, strict=True):
        assert g.terms == w.terms  # thigh = swing - knee / 2, knee = knee
        assert abs(g.constant - w.constant) < 1e-9
    np.testing.assert_allclose(got.gait.standing_pose(), want.gait.standing_pose(), atol=0.01)


def test_the_laikago_registers_and_stands(tmp_path, capsys, monkeypatch):
    code, out, err = run(
        capsys,
        "pybullet_data:laikago/laikago_toes_zup.urdf",
        "--out",
        str(tmp_path),
        "--name",
        "dog",
    )
    assert code == 0, err
    assert "standing check: it stands" in out
    text = (tmp_path / "dog-model.yaml").read_text()
    # The knee coupling a user found by hand: thigh = -19.8 deg - knee / 2.
    line = next(x for x in text.splitlines() if x.startswith("  FL_upper_leg_2_hip_motor_joint"))
    constant = float(line.split("constant_deg: ")[1].split(",")[0])
    slope = float(line.split("FL_knee: ")[1].split("}")[0])
    assert abs(constant - -19.8) < 1.0 and abs(slope - -0.5) < 0.01
    assert "# fit error" in line  # every derived value says how
    standing = stand_check(text, tmp_path / "dog-model.yaml", seconds=2.0)
    assert standing.tilt < 5.0 and 0.30 < standing.height < 0.40
    monkeypatch.setenv(PATH_VARIABLE, str(tmp_path))
    registry.reset()
    try:
        robot = registry.lookup("dog")
        assert robot.family == "legged" and robot.n_parameters == 25
        sim = make_robot("dog", workers=1)
        try:
            genes = np.random.default_rng(5).uniform(-1, 1, (2, 25))
            moved = sim.evaluate_primitives(genes, 1.0)
        finally:
            sim.close()
        assert np.all(np.isfinite(moved.x)) and np.abs(moved.x).max() > 0.01
    finally:
        registry.reset()


def test_a_y_up_urdf_is_turned_z_up_and_reads_as_its_z_up_self(tmp_path, capsys, a1_files):
    """The A1 turned Y-up (forward +z, left +x), read with --up y, is the A1 again."""
    yup = tmp_path / "a1_yup.urdf"
    to_yup = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]).T
    yup.write_text(turned_urdf_text(read_urdf(DATA / "a1" / "a1.urdf"), to_yup, "A1, Y-up"))
    code, _, err = run(capsys, str(yup), "--out", str(tmp_path / "out"))
    assert code == 1 and "is Y-up" in err and "pass --up y" in err and "\n" not in err.strip()
    code, out, err = run(capsys, str(yup), "--out", str(tmp_path / "out"), "--up", "y")
    assert code == 0, err
    assert "standing check: it stands" in out
    got = load_robot_settings(tmp_path / "out" / "a1_description-model.yaml")
    assert got.urdf == str((tmp_path / "out" / "a1_description.urdf").resolve())
    want = load_robot_settings(a1_files / "a1_description-model.yaml")
    assert got.gait.joint_names == want.gait.joint_names
    assert got.gait.oscillators == want.gait.oscillators
    for g, w in zip(got.gait.joints, want.gait.joints, strict=True):
        assert g.terms == w.terms and abs(g.constant - w.constant) < 1e-6
    assert got.footprint_radius == want.footprint_radius


LEG_LESS = '<robot name="brick"><link name="base"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1"/></inertial></link></robot>'  # noqa: E501


@pytest.mark.parametrize(
    ("urdf", "options", "message"),
    [
        ("pybullet_data:laikago/laikago_toes.urdf", (), "pass --up y, or use laikago_toes_zup"),
        ("pybullet_data:laikago/laikago_toes.urdf", ("--up", "y"), "zero inertias"),
        ("pybullet_data:laikago/laikago.urdf", (), "no foot links found"),
        ("pybullet_data:mini_cheetah/mini_cheetah.urdf", (), "inertias no rigid body has"),
        ("BROKEN", (), "not a readable URDF"),
        ("LEGLESS", (), "no foot links found"),
        ("NOTHERE", (), "no such file"),
    ],
)
def test_an_unusable_urdf_is_refused_in_one_line(tmp_path, capsys, urdf, options, message):
    if urdf == "BROKEN":
        urdf = tmp_path / "broken.urdf"
        urdf.write_text('<robot name="x"><link name="a">')
    elif urdf == "LEGLESS":
        urdf = tmp_path / "brick.urdf"
        urdf.write_text(LEG_LESS)
    elif urdf == "NOTHERE":
        urdf = tmp_path / "nothere.urdf"
    code, out, err = run(capsys, str(urdf), "--out", str(tmp_path / "out"), *options)
    assert code == 1 and out == ""
    assert message in err and err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
