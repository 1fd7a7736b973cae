"""Recording and replaying runs: rosbag2 bags in MCAP storage written without rosbag2, a
lockstep run recorded whole from its first cycle, and its replay into fresh evorbc nodes
making the recorded choices bit for bit."""

import contextlib
import json
import os
import re
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
import yaml
from graph_helpers import children, cmdline, graph_env
from install_helpers import assert_fatal_line
from mcap.reader import make_reader
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from ros_domains import claim_domain
from rosbags.rosbag2 import Reader

from sim_bridge import player
from sim_bridge.bringup import node_command
from sim_bridge.graph import sim_graph
from sim_bridge.lockstep_bag import Cycle, first_difference, load_recording, role_topics
from sim_bridge.rosbag_io import BagError, BagReader, BagWriter, decode, partial_path, typestore

#: ROS_DOMAIN_ID of each multi-process test (200-209 are this module's).
RECORD, PLAY, TAMPERED, RECORDER_ERRORS, RECORDER_STOP, LAGGING = 200, 201, 202, 203, 204, 205

#: The 4WS graph's topics and types (a type learnt from the graph comes too late for the
#: first cycles: test_a_topic_without_a_type_is_recorded_once_the_graph_shows_it).
RECORDED = {
    "/clock": "rosgraph_msgs/msg/Clock",
    "scan": "sensor_msgs/msg/LaserScan",
    "odom": "nav_msgs/msg/Odometry",
    "goal": "geometry_msgs/msg/PointStamped",
    "joint_states": "sensor_msgs/msg/JointState",
    "evorbc/rangefinders": "std_msgs/msg/Float64MultiArray",
    "evorbc/goal_sectors": "std_msgs/msg/Float64MultiArray",
    "evorbc/primitive": "std_msgs/msg/Float64MultiArray",
    "evorbc/mapping": "std_msgs/msg/Float64MultiArray",
    "steering_position_controller/commands": "std_msgs/msg/Float64MultiArray",
    "wheel_velocity_controller/commands": "std_msgs/msg/Float64MultiArray",
}
#: The recorded topics that the evorbc nodes publish (the others are the bridge's).
FROM_NODES = [t for t in RECORDED if t.startswith(("evorbc/", "steering", "wheel"))]
FLOATS = "std_msgs/msg/Float64MultiArray"


def recorder_command(bag, topics=RECORDED):
    return node_command(
        "sim_bridge.recorder",
        {
            "use_sim_time": True,
            "bag": str(bag),
            "topics": list(topics),
            "types": list(topics.values()),
        },
    )


def serialized(msgtype, **fields):
    """CDR bytes of a message built with rosbags (fields as rosbags' dataclasses take them)."""
    store = typestore()
    return store.serialize_cdr(store.types[msgtype](**fields), msgtype)


def clock(seconds):
    ns = round(seconds * 1e9)
    time_type = typestore().types["builtin_interfaces/msg/Time"]
    return time_type(sec=ns // 10**9, nanosec=ns % 10**9)


def genes_message(values):
    store = typestore()
    layout = store.types["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
    return serialized(FLOATS, layout=layout, data=np.asarray(values, np.float64))


# -- bags, written and read ---------------------------------------------------------------


def test_a_bag_is_written_under_a_partial_name_and_gets_its_own_when_closed(tmp_path):
    bag = tmp_path / "run"
    writer = BagWriter(bag)
    writer.add_topic("/evorbc/primitive", FLOATS)
    writer.write("/evorbc/primitive", 100, genes_message([1.0]))
    # While it is written nothing called "run" exists to be taken for a finished bag.
    assert not bag.exists() and partial_path(bag) == tmp_path / "run.partial"
    assert partial_path(bag).is_dir()
    assert writer.close() == bag
    assert sorted(p.name for p in bag.iterdir()) == ["metadata.yaml", "run.mcap"]
    assert not partial_path(bag).exists()


def test_an_existing_bag_and_an_unfinished_recording_are_refused_untouched(tmp_path):
    bag = tmp_path / "run"
    bag.mkdir()
    (bag / "keep.txt").write_text("a user's file")
    with pytest.raises(BagError, match=r"run exists; a bag is never overwritten"):
        BagWriter(bag)
    assert (bag / "keep.txt").read_text() == "a user's file"
    other = tmp_path / "other"
    BagWriter(other)  # left open, as by a recorder that is still running (or died)
    with pytest.raises(BagError, match=r"other\.partial exists: an unfinished recording"):
        BagWriter(other)


def test_an_aborted_recording_stays_partial_and_is_not_read_as_a_bag(tmp_path):
    bag = tmp_path / "run"
    writer = BagWriter(bag)
    writer.add_topic("/scan", "sensor_msgs/msg/LaserScan")
    writer.abort()
    assert not bag.exists() and (partial_path(bag) / "run" / "run.mcap").exists()
    with pytest.raises(BagError, match=r"run: no such bag \(only \S*run\.partial, an unfin"):
        BagReader(bag)
    with pytest.raises(BagError, match=r"run\.partial: an unfinished recording, not a bag"):
        BagReader(partial_path(bag))


def test_messages_come_back_as_recorded_bytes_in_recorded_order(tmp_path):
    bag = tmp_path / "run"
    first, second = genes_message([0.5, -0.0]), genes_message([np.nan, 1e-300])
    with BagWriter(bag) as writer:
        writer.add_topic("/goal", "geometry_msgs/msg/PointStamped", latched=True)
        writer.add_topic("/evorbc/primitive", FLOATS, depth=10)
        writer.write("/evorbc/primitive", 7, second)
        writer.write("/evorbc/primitive", 7, first)  # the same log time: arrival order kept
        writer.write("/evorbc/primitive", 9, first)
    with BagReader(bag) as reader:
        assert reader.topics["/evorbc/primitive"].count == 3
        got = list(reader.messages(["/evorbc/primitive"]))
    assert [(m.time_ns, m.raw) for m in got] == [(7, second), (7, first), (9, first)]
    assert decode(first, FLOATS).data.tobytes() == np.array([0.5, -0.0]).tobytes()
    # Jazzy's rosbag2 reads metadata up to version 8; the latched topic is offered latched.
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["version"] == 8 and info["storage_identifier"] == "mcap"
    qos = {
        t["topic_metadata"]["name"]: yaml.safe_load(t["topic_metadata"]["offered_qos_profiles"])
        for t in info["topics_with_message_count"]
    }
    assert qos["/goal"][0]["durability"] == 1 and qos["/goal"][0]["reliability"] == 1
    assert qos["/evorbc/primitive"][0]["durability"] == 2


def test_a_type_the_bag_could_not_describe_is_refused(tmp_path):
    with BagWriter(tmp_path / "run") as writer, pytest.raises(BagError, match="no definition"):
        writer.add_topic("/x", "my_msgs/msg/Secret")


def test_choices_are_compared_bit_for_bit():
    cycles = [Cycle(k * 100_000_000, None, b"", b"") for k in range(3)]
    same = [np.array([0.5, 1.0]), np.array([]), np.array([np.nan])]
    assert first_difference(same, [a.copy() for a in same], cycles) == ""
    assert first_difference(same[:2], same, cycles) == ""  # the final state's choice missing
    signed = [same[0], np.array([]), np.array([-np.nan])]
    assert first_difference(same, signed, cycles) == (
        "choices differ at cycle 2 (t = 0.200 s): recorded [nan], played [nan]"
    )
    ulp = [np.array([0.5, np.nextafter(1.0, 2.0)]), *same[1:]]
    assert first_difference(same, ulp, cycles) == (
        "choices differ at cycle 0 (t = 0.000 s): recorded [0.5, 1.0], "
        "played [0.5, 1.0000000000000002]"
    )


# -- the player's and the recorder's refusals --------------------------------------------


def header(seconds, frame):
    return typestore().types["std_msgs/msg/Header"](stamp=clock(seconds), frame_id=frame)


def sample(topic, seconds):
    """CDR bytes of a small message of the graph's ``topic`` at ``seconds``."""
    types = typestore().types
    if topic == "/clock":
        return serialized("rosgraph_msgs/msg/Clock", clock=clock(seconds))
    if topic == "/goal":
        point = types["geometry_msgs/msg/Point"](x=1.0, y=2.0, z=0.0)
        return serialized(
            "geometry_msgs/msg/PointStamped", header=header(seconds, "odom"), point=point
        )
    if topic == "/odom":
        odom = typestore().deserialize_cdr(ODOM_TEMPLATE, "nav_msgs/msg/Odometry")
        odom.header = header(seconds, "odom")
        return typestore().serialize_cdr(odom, "nav_msgs/msg/Odometry")
    return serialized(
        "sensor_msgs/msg/LaserScan",
        header=header(seconds, "base_link"),
        angle_min=0.0,
        angle_max=0.0,
        angle_increment=0.0,
        time_increment=0.0,
        scan_time=0.0,
        range_min=0.0,
        range_max=1.0,
        ranges=np.ones(1, np.float32),
        intensities=np.zeros(0, np.float32),
    )


#: An all-zero nav_msgs/Odometry (rclpy's default message), to stamp.
ODOM_TEMPLATE = serialize_message(Odometry())
TYPES = {
    "/clock": "rosgraph_msgs/msg/Clock",
    "/scan": "sensor_msgs/msg/LaserScan",
    "/odom": "nav_msgs/msg/Odometry",
    "/goal": "geometry_msgs/msg/PointStamped",
}


def small_bag(path, topics=tuple(TYPES), cycles=2, choices=0):
    """A lockstep bag of ``cycles`` cycles of ``topics`` and ``choices`` primitives."""
    with BagWriter(path) as writer:
        for topic in topics:
            writer.add_topic(topic, TYPES[topic])
        if "/goal" in topics:
            writer.write("/goal", 0, sample("/goal", 0.0))
        for k in range(cycles):
            for topic in set(topics) - {"/goal"}:
                writer.write(topic, k * 100_000_000, sample(topic, k * 0.1))
        if choices:
            writer.add_topic("/evorbc/primitive", FLOATS)
        for k in range(choices):
            writer.write("/evorbc/primitive", k * 100_000_000, genes_message([k]))
    return path


def play_main(capsys, *argv):
    status = player.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize(
    "case, expected",
    [
        ("missing", r"missing: no such bag"),
        ("folder", r"folder: not a rosbag2 bag \(no metadata\.yaml\)"),
        ("file", r"file\.txt: not a readable rosbag2 bag \(.*\)"),
        ("unfinished", r"unfinished\.partial: an unfinished recording, not a bag .*"),
        ("no scan", r"no scan: no /scan in the bag; it cannot be played"),
        ("no goal", r"no goal: no /goal in the bag; it cannot be played"),
    ],
)
def test_the_player_refuses_a_bad_bag_in_one_line(tmp_path, capsys, monkeypatch, case, expected):
    monkeypatch.chdir(tmp_path)
    Path("folder").mkdir()
    Path("file.txt").write_text("not a bag")
    BagWriter("unfinished").abort()
    small_bag(Path("no scan"), topics=("/clock", "/odom", "/goal"))
    small_bag(Path("no goal"), topics=("/clock", "/scan", "/odom"))
    name = {"file": "file.txt", "unfinished": "unfinished.partial"}.get(case, case)
    status, out, err = play_main(capsys, name)
    assert status == 2 and out == ""
    assert re.fullmatch(rf"evorbc-play: error: {expected}\n", err), err


def test_the_player_refuses_a_bag_whose_choices_do_not_fit_its_cycles(tmp_path, capsys):
    bag = small_bag(tmp_path / "none")
    status, _, err = play_main(capsys, bag, "--compare")
    assert (
        status == 2 and err == f"evorbc-play: error: {bag}: no /evorbc/primitive to compare with\n"
    )
    # A recorder that missed the first cycles has more choices than scans.
    bag = small_bag(tmp_path / "late", cycles=2, choices=4)
    status, _, err = play_main(capsys, bag, "--compare")
    assert status == 2 and err == (
        f"evorbc-play: error: {bag}: 4 recorded choices for 2 cycles (the first at "
        "t = 0.000 s); a complete lockstep recording has one per cycle\n"
    )


def test_the_player_finds_a_namespaced_graph_s_topics():
    assert role_topics("/robot1/") == {
        "scan": "/robot1/scan",
        "odom": "/robot1/odom",
        "goal": "/robot1/goal",
        "primitive": "/robot1/evorbc/primitive",
        "clock": "/clock",
    }
    assert role_topics()["scan"] == "/scan"


def test_a_bag_is_read_as_its_lockstep_cycles(tmp_path):
    recording = load_recording(small_bag(tmp_path / "run", cycles=3, choices=2))
    assert [c.stamp_ns for c in recording.cycles] == [0, 100_000_000, 200_000_000]
    assert recording.cycles[1].scan == sample("/scan", 0.1)
    assert recording.cycles[2].clock == sample("/clock", 0.2)
    assert recording.goal == sample("/goal", 0.0)
    assert [c.tolist() for c in recording.choices] == [[0.0], [1.0]]


def test_a_bad_player_option_is_one_line(tmp_path):
    done = subprocess.run(
        [sys.executable, "-P", "-m", "sim_bridge.player", str(tmp_path), "--timeout", "0"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr == (
        "evorbc-play: error: argument --timeout: expected a number of seconds > 0, got '0' "
        "(see evorbc-play --help)\n"
    )


@pytest.mark.parametrize(
    "params, start",
    [
        ({"bag": "run"}, "parameter topics must list the topics to record"),
        ({"bag": "run", "topics": "scan"}, "parameter topics must be a list of strings"),
        ({"bag": "run", "topics": ["scan"], "types": ["sensor_msgs/msg/Nope"]}, "parameter types"),
        ({"bag": "old", "topics": ["scan"]}, "parameter bag: old exists; a bag is never"),
    ],
    ids=["no topics", "not a list", "unknown type", "existing bag"],
)
def test_the_recorder_refuses_bad_parameters_in_one_fatal_line(tmp_path, params, start):
    (tmp_path / "old").mkdir()
    done = subprocess.run(
        node_command("sim_bridge.recorder", params),
        env=graph_env(RECORDER_ERRORS),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert_fatal_line(done, "recorder", start)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old"]  # nothing created


def test_the_recorder_closes_its_bag_on_sigterm(tmp_path):
    bag = tmp_path / "run"
    topics = {"scan": "sensor_msgs/msg/LaserScan", "evorbc/primitive": FLOATS}
    proc = subprocess.Popen(
        recorder_command(bag, topics),
        env=graph_env(RECORDER_STOP),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    seen = ""
    while "recording 2 topics" not in seen:
        line = proc.stderr.readline()
        assert line, f"the recorder ended early: {seen}"
        seen += line
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0 and "Traceback" not in seen + err
    with BagReader(bag) as reader:
        assert {t: v.count for t, v in reader.topics.items()} == {
            "/scan": 0,
            "/evorbc/primitive": 0,
        }
    assert not partial_path(bag).exists()


def test_a_topic_without_a_type_is_recorded_once_the_graph_shows_it(ros, tmp_path):
    from std_msgs.msg import Float64MultiArray

    from sim_bridge.recorder import RecorderNode

    bag = tmp_path / "run"
    recorder = ros.make(RecorderNode, bag=str(bag), topics=["later", "never"], types=["", ""])
    assert recorder.pending == ["/later", "/never"]
    pub = ros.publisher(Float64MultiArray, "later")
    assert ros.spin_until(lambda: "/later" in recorder.subs)
    ros.connected(pub)
    message = Float64MultiArray(data=[1.5])
    pub.publish(message)
    assert ros.spin_until(lambda: recorder.written == 1)
    assert recorder.pending == ["/never"]  # no publisher, no type: not in the bag
    assert recorder.close_bag()
    with BagReader(bag) as reader:
        assert {t: (v.msgtype, v.count) for t, v in reader.topics.items()} == {
            "/later": (FLOATS, 1)
        }
        # Compared decoded: the publisher's CDR alignment padding is not always zeros.
        raws = [m.raw for m in reader.messages(["/later"])]
    assert [decode(raw, FLOATS).data.tolist() for raw in raws] == [[1.5]]


def test_a_failed_write_stops_the_recording_naming_the_bag(ros, tmp_path):
    from std_msgs.msg import Float64MultiArray

    from sim_bridge.recorder import RecorderNode

    bag = tmp_path / "run"
    recorder = ros.make(RecorderNode, bag=str(bag), topics=["x"], types=[FLOATS])

    def full(*args):
        raise OSError(28, "No space left on device")

    recorder.bag.writer.write = full
    pub = ros.publisher(Float64MultiArray, "x")
    ros.connected(pub)
    pub.publish(Float64MultiArray(data=[1.0]))
    with pytest.raises(BagError, match=rf"^{re.escape(str(bag))}: cannot write \(No space left"):
        ros.spin_until(lambda: False, timeout=10)
    recorder.bag.abort()
    recorder.bag = None  # stays partial, as the recorder leaves it
    assert partial_path(bag).exists() and not bag.exists()


# -- a lockstep run, recorded and played back --------------------------------------------


def stop_all(procs):
    """SIGINT, then SIGKILL after 5 s (as evorbc-sim stops its graph)."""
    for p in procs:
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
    for p in procs:
        try:
            p.wait(5)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """A whole lockstep run in gaps, recorded by ``evorbc-sim --bag``: (bag, bridge result,
    evorbc-sim's status, its output).

    evorbc-sim starts the recorder with the rest; the bridge holds its first state until
    the recorder says it hears every topic (``recorder/ready``). Without that wait, a
    recorder started with the graph missed the first 0 to 139 cycles of some topics in 3
    of 5 runs: a DDS participant hears of one started after it only at that one's next
    periodic announcement (Fast DDS: every 3 s).
    """
    tmp = tmp_path_factory.mktemp("recorded")
    bag, result = tmp / "gaps-run", tmp / "result.json"
    done = subprocess.run(
        [sys.executable, "-P", "-m", "sim_bridge.bringup", "--maze", "gaps", "--bag", str(bag),
         "--result", str(result), "--plot", str(tmp / "run.png"),
         "--domain-id", str(claim_domain(RECORD))],
        env=graph_env(RECORD), capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    (tmp / "graph.log").write_text(done.stdout + done.stderr)  # for a failure
    return bag, json.loads(result.read_text()), done.returncode, done.stdout + done.stderr


def start_evorbc_nodes(domain, log):
    """Fresh laser_sensor, radar_sensor and arbitrator as the graph runs them."""
    graph = sim_graph(maze="gaps")
    return [
        subprocess.Popen(
            node_command(spec.module, spec.parameters, spec.param_file),
            env=graph_env(domain),
            stdout=log,
            stderr=subprocess.STDOUT,
        )
        for spec in (graph.node(n) for n in ("laser_sensor", "radar_sensor", "arbitrator"))
    ]


def play(bag, domain, tmp_path):
    """``evorbc-play BAG --compare`` into fresh nodes in ``domain``."""
    with open(tmp_path / f"nodes-{domain}.log", "w") as log:
        nodes = start_evorbc_nodes(domain, log)
        try:
            return subprocess.run(
                [sys.executable, "-P", "-m", "sim_bridge.player", str(bag), "--compare"],
                env=graph_env(domain),
                capture_output=True,
                text=True,
                timeout=300,
            )
        finally:
            stop_all(nodes)


@pytest.mark.slow
def test_a_lockstep_run_is_recorded_whole_from_its_first_cycle(recorded):
    bag, result, status, out = recorded
    assert status == 0 and "Traceback" not in out, out
    assert f"recorded {bag} (evorbc-play {bag} --compare plays it back)" in out
    assert result["reached"] and not partial_path(bag).exists()
    cycles = len(result["trajectory"]) - 1
    states = cycles + 1  # the bridge publishes its final state too
    with Reader(bag) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        # Log times are the recorder's simulated clock, not the wall clock.
        assert reader.end_time <= round(result["time"] * 1e9) + 1
    for topic in ("/clock", "/scan", "/odom", "/joint_states"):
        assert counts[topic] == states, (topic, counts)
    assert counts["/goal"] == 1
    # One choice (and one reading of each sensor) per state; the final state's may be cut
    # short by the graph's shutdown, and the arbitrator's deactivation then sends one more,
    # empty primitive (stop), which belongs to no cycle.
    assert counts["/evorbc/primitive"] in (cycles, states, states + 1)
    assert len(load_recording(bag).choices) in (cycles, states)
    for topic in ("/evorbc/rangefinders", "/evorbc/goal_sectors", "/evorbc/mapping"):
        assert counts[topic] in (cycles, states), (topic, counts)
    for topic in ("/steering_position_controller/commands", "/wheel_velocity_controller/commands"):
        assert counts[topic] >= cycles, (topic, counts)
    recording = load_recording(bag)
    stamps = np.array([c.stamp_ns for c in recording.cycles])
    assert stamps[0] == 0 and np.all(np.abs(np.diff(stamps) - 100_000_000) <= 1)
    assert all(c.clock is not None for c in recording.cycles)


@pytest.mark.slow
def test_a_recorder_behind_at_the_end_of_the_run_still_gets_all_of_it(tmp_path):
    # The recorder is frozen from t = 50 s of the 81.9 s run until 3 s after the bridge's
    # last progress line (t = 80 s), as a loaded machine may leave it cycles behind: the
    # bridge must not end, and the graph be stopped, before the recorder holds its final
    # states. (The bridge's streams keep 1000 unacknowledged samples, more than the 320
    # cycles frozen; a DDS lease, 20 s, is far longer than the freeze.) Without the wait
    # the bag held 528 of the 819. The nodes' last choices are not checked here:
    # they wait 0.5 s for acknowledgement (LAST_WORDS), less than the freeze.
    bag, result = tmp_path / "gaps-run", tmp_path / "result.json"
    proc = subprocess.Popen(
        [sys.executable, "-P", "-m", "sim_bridge.bringup", "--maze", "gaps", "--bag", str(bag),
         "--result", str(result), "--plot", str(tmp_path / "run.png"),
         "--domain-id", str(claim_domain(LAGGING))],
        env=graph_env(LAGGING), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    seen, recorder, thawed = [], None, None
    try:
        for line in proc.stdout:
            seen.append(line)
            if recorder is None and re.search(r"\[sim_bridge\]: t = +50\.0 s", line):
                found = [p for p in children(proc.pid) if "sim_bridge.recorder" in cmdline(p)]
                assert len(found) == 1, "".join(seen)
                recorder = found[0]
                os.kill(recorder, signal.SIGSTOP)
            elif recorder is not None and re.search(r"\[sim_bridge\]: t = +80\.0 s", line):
                thawed = threading.Timer(3.0, os.kill, (recorder, signal.SIGCONT))
                thawed.start()
        proc.wait(timeout=120)
    finally:
        if recorder is not None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(recorder, signal.SIGCONT)
        if proc.poll() is None:
            proc.kill()
    out = "".join(seen)
    assert thawed is not None, out  # the run got from t = 50 s to t = 80 s
    assert proc.returncode == 0 and "Traceback" not in out, out
    states = len(json.loads(result.read_text())["trajectory"])
    with BagReader(bag) as reader:
        counts = {t: v.count for t, v in reader.topics.items()}
    (tmp_path / "graph.log").write_text(out)  # the whole graph's output, for a failure
    warned = [line for line in seen if "WARN" in line]  # what the graph said went wrong
    for topic in ("/clock", "/scan", "/odom", "/joint_states"):
        assert counts[topic] == states, (topic, counts, warned)
    assert len(load_recording(bag).cycles) == states


@pytest.mark.slow
def test_the_mcap_file_carries_every_schema_for_other_tools(recorded):
    bag, *_ = recorded
    with Reader(bag) as reader:
        types = {c.topic: c.msgtype for c in reader.connections}
        counts = {c.topic: c.msgcount for c in reader.connections}
    with open(bag / "gaps-run.mcap", "rb") as f:
        mcap = make_reader(f)
        assert mcap.get_header().profile == "ros2"
        summary = mcap.get_summary()
        channels = {c.topic: c for c in summary.channels.values()}
        assert set(channels) == set(types)
        for topic, channel in channels.items():
            schema = summary.schemas[channel.schema_id]
            assert channel.message_encoding == "cdr"
            assert schema.name == types[topic] and schema.encoding == "ros2msg"
            definition, _ = typestore().generate_msgdef(types[topic], ros_version=2)
            assert schema.data.decode() == definition
            assert summary.statistics.channel_message_counts[channel.id] == counts[topic]
        assert sum(1 for _ in mcap.iter_messages()) == sum(counts.values())
    scan = summary.schemas[channels["/scan"].schema_id].data.decode()
    assert "MSG: std_msgs/Header" in scan  # nested definitions included


@pytest.mark.slow
def test_the_bag_played_into_fresh_nodes_gives_the_recorded_choices_bit_for_bit(recorded, tmp_path):
    bag, *_ = recorded
    n = len(load_recording(bag).choices)
    done = play(bag, PLAY, tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f"{n} of {n} choices equal"), done.stdout
    assert "Traceback" not in done.stderr


@pytest.mark.slow
def test_a_recorded_choice_off_by_one_ulp_is_named_with_its_cycle(recorded, tmp_path):
    bag, *_ = recorded
    k = 100
    changed = tmp_path / "changed"
    seen = 0
    with BagReader(bag) as reader, BagWriter(changed) as writer:
        for topic, info in reader.topics.items():
            writer.add_topic(topic, info.msgtype, latched=topic == "/goal")
        for m in reader.messages(reader.topics):
            raw = m.raw
            if m.topic == "/evorbc/primitive":
                if seen == k:
                    msg = decode(raw, FLOATS)
                    original = msg.data.copy()
                    msg.data = original.copy()
                    msg.data[0] = np.nextafter(original[0], np.inf)
                    raw = typestore().serialize_cdr(msg, FLOATS)
                seen += 1
            writer.write(m.topic, m.time_ns, raw)
    done = play(changed, TAMPERED, tmp_path)
    assert done.returncode == 1 and done.stdout == ""
    played = [repr(float(v)) for v in original]
    recorded_genes = [repr(float(np.nextafter(original[0], np.inf))), *played[1:]]
    assert done.stderr == (
        f"evorbc-play: choices differ at cycle {k} (t = 10.000 s): recorded "
        f"[{', '.join(recorded_genes)}], played [{', '.join(played)}]\n"
    )
