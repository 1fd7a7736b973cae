"""The lockstep ROS 2 graph with a dropout relay between the bridge's ``scan`` and the laser
node (tests/test_laser_graph.py and bench/bench_laser.py ``--graph``)."""

import json
import subprocess
import sys
from pathlib import Path

from graph_helpers import GraphRun

from sim_bridge.bringup import node_command

RELAY = Path(__file__).with_name("scan_dropout_relay.py")
#: 10 deg between the 0 and 60 deg rangefinders, as a mast or a cable would blank.
DEAD_SECTOR = [25.0, 35.0]


class DropoutRun(GraphRun):
    """The lockstep graph with the dropout relay (tests/scan_dropout_relay.py) feeding the
    laser node; ``counts()`` gives the scans relayed and the readings published."""

    def __init__(self, tmp_path, domain, maze, dropout, dead_sector, seed=1, arbitrator=None):
        self.relay_params = {
            "dropout": dropout,
            "dead_sector": dead_sector,
            "seed": seed,
            "count_file": str(tmp_path / "counts.json"),
        }
        super().__init__(tmp_path, domain, maze, arbitrator=arbitrator)

    def start(self, name, module, params):
        if name == "sim_bridge":
            ros_args = node_command("relay", self.relay_params)[3:]  # from --ros-args on
            relay = [sys.executable, str(RELAY), *ros_args]
            self.spawn("scan_dropout_relay", relay)
            if self.relay_params["dropout"] > 0:
                # A refused scan leaves the bridge without commands: send the state again
                # soon. Not without dropouts: a cycle slower than this under load would be
                # answered twice and shift every later choice (the bridge's
                # wait_for_commands).
                params = {**params, "lockstep_timeout": 1.0}
        cmd = node_command(module, params)
        if name == "laser_sensor":
            cmd += ["-r", "scan:=scan_dropped"]
        return self.spawn(name, cmd)

    def spawn(self, name, cmd):
        proc = subprocess.Popen(
            cmd, env=self.env, stdout=self.log, stderr=subprocess.STDOUT, start_new_session=True
        )
        self.procs[name] = proc
        return proc

    def counts(self):
        return json.loads(Path(self.relay_params["count_file"]).read_text())
