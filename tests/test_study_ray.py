"""evorbc-study on a real two-node Ray cluster on localhost, losing a node mid-run."""

import json
import subprocess
from datetime import datetime

import pytest
from ray_cluster import LocalCluster, free_port
from study_helpers import (
    checkpoints,
    results_contents,
    run_study,
    study_command,
    wait_for,
    write_tiny_study,
)

pytest.importorskip("ray")


@pytest.fixture
def cluster():
    c = LocalCluster()
    yield c
    c.stop()


@pytest.mark.slow
def test_a_study_survives_losing_a_node_with_results_identical_to_a_serial_run(
    cluster, tmp_path, serial_results
):
    study = write_tiny_study(tmp_path)

    results = tmp_path / "ray"
    proc = subprocess.Popen(
        study_command("run", study, "--results", results, "--address", cluster.address),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=cluster.env,
    )
    # Both runs go at once, one per node; once both have saved a NEAT checkpoint (so
    # neither has finished), the worker node is lost with the run it was running.
    wait_for(lambda: checkpoints(results) == 2, 300, "both runs' NEAT checkpoints")
    cluster.kill_worker_node()
    out, _ = proc.communicate(timeout=600)
    assert proc.returncode == 0, out
    assert "study tiny: 2 done, 0 running, 0 left" in out
    logs = [p.read_text() for p in results.rglob("run.log")]
    assert any(log.count("$ evorbc-evolve arbitrator") == 2 for log in logs)  # retried
    # ... from its checkpoint, not from the start.
    assert any("resuming from the checkpoint: generations 1-" in log for log in logs)
    assert results_contents(results) == results_contents(serial_results)


def test_an_unreachable_cluster_is_one_line(tmp_path):
    study = write_tiny_study(tmp_path)
    result = run_study(
        "run", study, "--results", tmp_path / "r", "--address", f"127.0.0.1:{free_port()}",
        timeout=120,
    )  # fmt: skip
    assert result.returncode == 1
    lines = result.stderr.strip().splitlines()
    assert lines[-1].startswith("evorbc-study: error: --address 127.0.0.1:")
    assert "cannot connect to the Ray cluster" in lines[-1]


@pytest.mark.slow
def test_spread_runs_queue_one_at_a_time_with_results_identical_to_a_serial_run(
    cluster, tmp_path, serial_results
):
    """``--spread 1``: the runs ask Ray for no CPU and are handed out one at a time (the
    second from the queue when the first ends), each with the cluster's address for its
    simulations (a no-op for the 2WS kernel); the results are the serial runner's."""
    study = write_tiny_study(tmp_path)
    results = tmp_path / "spread"
    result = subprocess.run(
        study_command("run", study, "--results", results, "--address", cluster.address,
                      "--spread", "1"),
        capture_output=True, text=True, timeout=600, env=cluster.env,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "study tiny: 2 done, 0 running, 0 left" in result.stderr
    # The first run's end hands out the second: their times (run.json: finished, and wall
    # seconds before it) do not overlap, though Ray had CPUs for both at once.
    spans = []
    for record in results.rglob("run.json"):
        data = json.loads(record.read_text())
        end = datetime.fromisoformat(data["finished"]).timestamp()
        spans.append((end - data["seconds"], end))
    (_, first_end), (second_start, _) = sorted(spans)
    assert first_end <= second_start + 1.0  # 1 s: "finished" is rounded to the second
    assert results_contents(results) == results_contents(serial_results)
