"""Bad arbitrator and repertoire files, and bad evorbc-sim / replay options: one line each.

Everything here is refused before any simulation or ROS node starts, so the tests are fast.
"""

import json
import subprocess
import sys

import pytest

from evorbc_ros.arbitrator import ArbitratorError, ArbitratorFile
from evorbc_ros.config import ConfigError, load_yaml_mapping
from evorbc_ros.defaults import default_arbitrator, default_repertoire
from evorbc_ros.repertoire import METRICS, Repertoire, RepertoireError
from offline_evolution import cli
from offline_evolution.commands import replay
from offline_evolution.quality import METRICS as OFFLINE_METRICS
from offline_evolution.runs import replay as replay_runs
from offline_evolution.runs.errors import UserError
from sim_bridge import bringup

ARB = json.loads(default_arbitrator().read_text())
REP = json.loads(default_repertoire().read_text())
#: The shipped arbitrator's input count (the paper's layout gives 10; a default with another
#: layout, other numbers).
N_IN = len(ARB["inputs"])


def write(tmp_path, name, data, edit=None):
    """A copy of ``data`` (deep), edited in place by ``edit``, written as JSON."""
    data = json.loads(json.dumps(data))
    if edit:
        edit(data)
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return path


def one_line(error_type, load, path):
    with pytest.raises(error_type) as info:
        load(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message


def other_robot(data):
    """The shipped 4ws-5 repertoire turned into a consistent 4ws-3 one (3 genes)."""
    data["robot"] = "4ws-3"
    data["parameters"] = data["parameters"][:3]
    data["primitives"]["genes"] = [g[:3] for g in data["primitives"]["genes"]]


# -- arbitrator files ----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("edit", "needle"),
    [
        (lambda d: d.update(control_period="abc"), "control_period must be a number of seconds"),
        (lambda d: d.update(control_period=-1), "control_period must be a number of seconds"),
        (lambda d: d.update(control_period=True), "control_period must be a number of seconds"),
        (lambda d: d.update(evolution="x"), "evolution must be a mapping, got 'x'"),
        (lambda d: d.update(evolution=[1]), "evolution must be a mapping, got [1]"),
        (lambda d: d["evolution"].update(task="bad"), "evolution.task must be a mapping"),
        (lambda d: d["repertoire"].update(file=5), "repertoire.file must be a plain file name"),
        (
            lambda d: d["repertoire"].update(file="../../../etc/passwd"),
            "repertoire.file must be a plain file name (no folder), got '../../../etc/passwd'",
        ),
        (lambda d: d["repertoire"].update(file=".."), "repertoire.file must be a plain"),
        (
            lambda d: d["inputs"].__setitem__(0, "x"),
            "inputs do not match the sensors section (inputs[0] is 'x', the sensor layout's "
            "is 'range_000')",
        ),
        (lambda d: d["inputs"].pop(), f"{N_IN - 1} input names, the sensor layout gives {N_IN}"),
        (lambda d: d.pop("inputs"), f"inputs must list the {N_IN} input names"),
        (lambda d: d.pop("sensors_fingerprint"), "missing key sensors_fingerprint"),
        (lambda d: d.update(robot="foo"), "robot 'foo' is not known; known robots: 2ws-2"),
        (lambda d: d.update(robot=5), "robot 5 is not known"),
    ],
)
def test_bad_arbitrator_files_are_refused_in_one_line(tmp_path, edit, needle):
    path = write(tmp_path, "a.json", ARB, edit)
    assert needle in one_line(ArbitratorError, ArbitratorFile.load, path)


def test_an_arbitrator_may_name_no_repertoire_file_and_record_no_evolution(tmp_path):
    def edit(d):
        d["repertoire"]["file"] = None
        d.pop("evolution")

    arb = ArbitratorFile.load(write(tmp_path, "a.json", ARB, edit))
    assert arb.evolution == {} and arb.repertoire["file"] is None


def test_a_standard_controller_must_drive_all_of_its_robots_parameters(tmp_path):
    def edit(d):  # the shipped network has 2 outputs: one per parameter, 3 are needed
        d.update(kind="standard", robot="4ws-3")
        d["parameters"] = [{"name": n, "unit": "u", "low": -1, "high": 1} for n in "ab"]

    path = write(tmp_path, "s.json", ARB, edit)
    message = one_line(ArbitratorError, ArbitratorFile.load, path)
    assert message == f"{path}: robot 4ws-3 has 3 parameters, the file has 2"


# -- repertoire files ----------------------------------------------------------------------


def hexapod_with_five_genes(d):
    d["robot"] = "hexapod"


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda d: d.update(robot="foo"),
            "robot 'foo' is not known; known robots: 2ws-2, 2ws-3, 4ws-3, 4ws-5, hexapod",
        ),
        (lambda d: d.update(robot="4ws-3"), "robot 4ws-3 has 3 parameters, the file has 5"),
        (hexapod_with_five_genes, "robot hexapod has 37 parameters, the file has 5"),
        (
            lambda d: d.update(metric="bogus"),
            "metric must be one of circular, radial, distance, distance+circular, "
            "distance+radial, circular+tilt, got 'bogus'",
        ),
        (
            lambda d: d["archive"].update(dims="abc"),
            "archive.dims must be 2 positive integers, got 'abc'",
        ),
        (lambda d: d["archive"].update(dims=[21, 0]), "archive.dims must be 2 positive"),
        (lambda d: d["archive"].update(kind="hex"), "archive.kind must be grid or cvt"),
        (lambda d: d["archive"].update(low=[0.5, 0.5]), "archive.low must be below archive.high"),
        (lambda d: d["archive"].update(high="x"), "archive.high must be 2 finite numbers"),
        (
            lambda d: d["algorithm"].update(simulation="x"),
            "algorithm.simulation must be a mapping, got 'x'",
        ),
        (
            lambda d: d["primitives"].update(genes=[], behaviour=[], heading=[], quality=[]),
            "the repertoire has no primitives",
        ),
    ],
)
def test_bad_repertoire_files_are_refused_in_one_line(tmp_path, edit, message):
    path = write(tmp_path, "r.json", REP, edit)
    assert one_line(RepertoireError, Repertoire.load, path).startswith(f"{path}: {message}")


def test_the_onboard_metric_names_are_the_offline_metrics():
    assert set(METRICS) == set(OFFLINE_METRICS)


def test_absurdly_nested_json_and_yaml_are_refused_in_one_line(tmp_path):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    for error, load, what in (
        (ArbitratorError, ArbitratorFile.load, "arbitrator"),
        (RepertoireError, Repertoire.load, "repertoire"),
    ):
        message = one_line(error, load, deep)
        assert message == f"{deep}: corrupt {what} file (invalid JSON: nested too deeply)"
    yaml_file = tmp_path / "deep.yaml"
    yaml_file.write_text("[" * 100_000 + "]" * 100_000)
    assert "nested too deeply" in one_line(ConfigError, load_yaml_mapping, yaml_file)


# -- the repertoire an arbitrator runs with ------------------------------------------------


def test_a_repertoire_for_another_robot_is_refused_even_when_mismatches_are_allowed(tmp_path):
    arb = ArbitratorFile.load(default_arbitrator())
    other = Repertoire.load(write(tmp_path, "r43.json", REP, other_robot))
    for allow in (False, True):
        with pytest.raises(ArbitratorError) as info:
            arb.check_repertoire(other, "r43.json", allow_mismatch=allow, waiver="--allow")
        assert str(info.value) == (
            "repertoire r43.json does not match the arbitrator: it is for robot 4ws-3, "
            "the arbitrator for 4ws-5"
        )


def test_another_fingerprint_names_the_callers_waiver_only_if_there_is_one(tmp_path):
    def turn(d):  # the fingerprint covers genes, behaviour and heading
        d["primitives"]["heading"][0] += 1.0

    arb = ArbitratorFile.load(default_arbitrator())
    other = Repertoire.load(write(tmp_path, "r.json", REP, turn))
    with pytest.raises(ArbitratorError) as info:
        arb.check_repertoire(other, "r.json")
    assert str(info.value).endswith("the arbitrator was evolved with c7bb8df06d1b")
    with pytest.raises(ArbitratorError, match=r"\(pass --allow-mismatch to use it anyway\)$"):
        arb.check_repertoire(other, "r.json", waiver="--allow-mismatch")
    assert len(arb.check_repertoire(other, "r.json", allow_mismatch=True)) == 1


# -- evorbc-evolve replay ------------------------------------------------------------------


def run_evolve(capsys, *argv):
    code = cli.main(list(argv))
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "\n".join(err)
    return code, err


def test_replay_refuses_a_repertoire_of_another_robot_despite_allow_mismatch(tmp_path, capsys):
    rep = write(tmp_path, "r43.json", REP, other_robot)
    code, err = run_evolve(
        capsys,
        "replay",
        "--arbitrator",
        str(default_arbitrator()),
        "--repertoire",
        str(rep),
        "--allow-mismatch",
    )
    assert code == 1 and err == [
        f"evorbc-evolve: error: repertoire {rep} does not match the arbitrator: it is for "
        "robot 4ws-3, the arbitrator for 4ws-5"
    ]


def test_replay_names_its_own_option_for_a_mismatch_it_can_waive(tmp_path, capsys):
    arb = write(tmp_path, "a.json", ARB, lambda d: d["repertoire"].update(fingerprint="0" * 64))
    code, err = run_evolve(
        capsys, "replay", "--arbitrator", str(arb), "--repertoire", str(default_repertoire())
    )
    assert code == 1 and len(err) == 1
    assert err[0].endswith("evolved with 000000000000 (pass --allow-mismatch to use it anyway)")


@pytest.mark.parametrize(
    ("name", "needle"),
    [("run.xyz", "--plot {path}: not a picture format"), ("", "--plot {path}: is a folder")],
)
def test_replay_checks_the_picture_path_before_loading_anything(tmp_path, capsys, name, needle):
    path = tmp_path / name
    code, err = run_evolve(capsys, "replay", "--arbitrator", "missing.json", "--plot", str(path))
    assert code == 1 and len(err) == 1 and needle.format(path=path) in err[0]


def test_replay_refuses_an_arbitrator_evolved_on_another_simulated_robot(tmp_path, capsys):
    # The 4WS kinematics record no simulation, so any recorded one is another robot.
    arb = write(
        tmp_path,
        "a.json",
        ARB,
        lambda d: d["evolution"].update(simulation={"geometry": {"tibia_length": 0.14}}),
    )
    code, err = run_evolve(capsys, "replay", "--arbitrator", str(arb), "--maze", "obstacle")
    assert code == 1 and len(err) == 1
    assert err[0].startswith(f"evorbc-evolve: error: {arb}: was evolved for a different robot")


def test_replay_design_check_names_the_file_and_first_setting_that_differs(tmp_path):
    arb = ArbitratorFile.load(default_arbitrator())
    rep = Repertoire.load(default_repertoire())
    now = {"geometry": {"tibia_length": 0.10}}
    replay_runs.check_design(None, arb, "a.json", rep, "r.json")  # nothing recorded: passes
    rep.algorithm = {"simulation": {"geometry": {"tibia_length": 0.14}}}
    with pytest.raises(RepertoireError, match=r"^r.json: .*tibia_length is 0.14 in the rep"):
        replay_runs.check_design(now, arb, "a.json", rep, "r.json")
    arb.evolution = {"simulation": {"geometry": {"tibia_length": 0.12}}}
    with pytest.raises(UserError, match=r"^a.json: .*tibia_length is 0.12 in the arbitrator"):
        replay_runs.check_design(now, arb, "a.json", None, None)


def test_evorbc_evolve_reports_an_unexpected_failure_in_one_line(capsys, monkeypatch):
    def broken(args):
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(replay, "cmd_replay", broken)
    monkeypatch.delenv("EVORBC_DEBUG", raising=False)
    code, err = run_evolve(capsys, "replay", "--arbitrator", "a.json")
    assert code == 1 and err == [
        "evorbc-evolve: internal error: RuntimeError: boom second line "
        "(set EVORBC_DEBUG=1 for a traceback)"
    ]


# -- evorbc-sim ----------------------------------------------------------------------------


def run_sim(capsys, *argv):
    code = bringup.main(list(argv))
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "\n".join(err)
    return code, err


@pytest.fixture
def no_graph(monkeypatch):
    """Fail the test if evorbc-sim would start a node."""

    def refuse(*args, **kwargs):
        raise AssertionError("a node was started")

    monkeypatch.setattr(bringup, "start_graph", refuse)


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--plot", "run.xyz"], "--plot run.xyz: not a picture format that can be written"),
        (["--plot", "."], "--plot .: is a folder, expected a file name"),
        (["--plot", "f.txt/run.png"], "--plot f.txt/run.png: cannot create folder"),
        (["--result", "f.txt/r.json"], "--result f.txt/r.json: cannot create folder"),
        (["--start", "bogus"], "--start must be nominal, random or 'x,y,heading_deg', got 'bogus'"),
        (["--start", "1,2"], "--start must be nominal, random or 'x,y,heading_deg', got '1,2'"),
        (["--start", "nan,0,0"], "--start must be finite, got 'nan,0,0'"),
        (["--start", "100,100,0"], "--start 100,100,0: (100.00, 100.00) m is outside maze"),
        (["--start=-3.5,0,0"], "--start: (-3.50, 0.00) m is 0.015 m from a wall"),
    ],
)
def test_evorbc_sim_refuses_bad_options_before_starting_a_node(
    tmp_path, capsys, monkeypatch, no_graph, argv, message
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "f.txt").write_text("not a folder")
    code, err = run_sim(capsys, "--quiet", *argv)
    assert code == 2 and len(err) == 1
    assert err[0].startswith(f"evorbc-sim: error: {message}")


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--start", "random", "--seed", "-1"], "argument --seed: expected an integer >= 0"),
        (["--domain-id", "500"], "argument --domain-id: expected an integer from 0 to 232"),
    ],
)
def test_evorbc_sim_options_out_of_range_are_usage_errors(capsys, argv, needle):
    with pytest.raises(SystemExit) as info:
        bringup.main(argv)
    assert info.value.code == 2 and needle in capsys.readouterr().err


def test_evorbc_sim_files_are_refused_without_suggesting_an_option_it_lacks(
    tmp_path, capsys, no_graph
):
    arb = write(tmp_path, "a.json", ARB, lambda d: d["repertoire"].update(fingerprint="0" * 64))
    code, err = run_sim(capsys, "--arbitrator", str(arb))
    assert code == 2 and len(err) == 1
    assert err[0].endswith("the arbitrator was evolved with 000000000000")
    bad = write(tmp_path, "cp.json", ARB, lambda d: d.update(control_period="abc"))
    code, err = run_sim(capsys, "--arbitrator", str(bad))
    assert code == 2 and err == [
        f"evorbc-sim: error: {bad}: control_period must be a number of seconds > 0, got 'abc'"
    ]


def test_evorbc_sim_reports_an_unexpected_failure_in_one_line(capsys, monkeypatch):
    def broken(args):
        raise RuntimeError("boom")

    monkeypatch.setattr(bringup, "prepare", broken)
    monkeypatch.delenv("EVORBC_DEBUG", raising=False)
    assert run_sim(capsys)[1] == [
        "evorbc-sim: internal error: RuntimeError: boom (set EVORBC_DEBUG=1 for a traceback)"
    ]
    monkeypatch.setenv("EVORBC_DEBUG", "1")
    with pytest.raises(RuntimeError, match="boom"):
        bringup.main([])


def test_evorbc_sim_drops_an_old_result_and_stops_its_nodes_whatever_fails(
    tmp_path, capsys, monkeypatch
):
    old = tmp_path / "r.json"
    old.write_text('{"reached": true}')  # an earlier run's: must not pass for this one's
    started = []

    def start_then_fail(graph, args, robot, arb_path, result_file):
        assert not old.exists()
        cmd = [sys.executable, "-c", "import time; time.sleep(60)"]
        started.append(subprocess.Popen(cmd))
        graph.procs["laser_sensor"] = started[0]
        raise RuntimeError("lost the graph")

    monkeypatch.setattr(bringup, "start_graph", start_then_fail)
    code, err = run_sim(capsys, "--quiet", "--result", str(old), "--plot", str(tmp_path / "p.png"))
    assert code == 1 and err[-1].startswith("evorbc-sim: internal error: RuntimeError")
    assert started[0].poll() is not None, "a node outlived evorbc-sim"
