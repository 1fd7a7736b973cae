"""The hexapod (paper Sec. V, docs/design.md section 11), registered."""

from __future__ import annotations

from evorbc_ros.robots.hexapod import HEXAPOD, SPEED_BOUND, HexapodGeometry, parameter_specs
from evorbc_ros.robots.record import Robot, SettingsFiles

ROBOTS = (
    Robot(
        name=HEXAPOD,
        description="18-joint hexapod in PyBullet, 37-parameter periodic gait (eq. 10-11)",
        parameters=parameter_specs(),
        settings=SettingsFiles(
            repertoire="repertoire/hexapod.yaml",
            arbitrator="arbitrator/hexapod.yaml",
            neat="neat/hexapod.ini",
            task="tasks/maze-hexapod.yaml",
        ),
        commands="evorbc_ros.nodes.trajectory_commands:JointTrajectoryCommands",
        command_topics=("joint_trajectory_controller/joint_trajectory",),
        sensors="sensors/hexapod.yaml",
        maze="hexapod",
        episode_time=30.0,  # s, paper Table I (hexapod)
        footprint_radius=HexapodGeometry().footprint_radius,
        max_speed=SPEED_BOUND,
        # Its simulation, bridge adapter, design check (the bridge simulates one design and
        # one laser, docs/design.md section 11) and maze task are the family's.
        family="hexapod",
        # Its repertoire's simulated time in generations of 150 x 30 s episodes
        # (paper Appendix E; docs/paper-check.md).
        equal_budget_generations=455,
        # Its episodes also carry their network and results between processes.
        episode_bytes=16_000,
        shipped_repertoire="hexapod.repertoire.json",
        shipped_arbitrator="hexapod.arbitrator.json",
        # Trained in the paper's setting only (paper Table I); the shipped one from it with
        # starts anywhere in the maze (evorbc_ros/data/README.md, docs/generalisation.md).
        paper_arbitrator="hexapod-paper.arbitrator.json",
    ),
)
