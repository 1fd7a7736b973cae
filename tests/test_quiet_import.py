"""pybullet's build-time banner stays out of the tools' stderr (errors are one line)."""

import subprocess
import sys


def test_importing_the_simulation_prints_nothing():
    code = "import sim_bridge.hexapod.physics, sim_bridge.pybullet_world; print('ok')"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout == "ok\n" and out.stderr == ""
