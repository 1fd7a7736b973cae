"""The simulation bridge's parameters as data (:mod:`evorbc_ros.node_parameters`'s way).

Declared by the bridge node at start-up, whichever robot it simulates, so one parameter
file (``config/ros/sim_bridge.yaml``) serves every robot; the robot adapters read theirs
from it (docs/design.md section 9).
"""

from __future__ import annotations

from evorbc_ros.node_parameters import COMMON, spec

PARAMETERS = (
    spec("maze", "obstacle", "maze name (config/mazes) or maze YAML file"),
    spec(
        "maze_scale",
        0.0,
        "factor (>= 1) the maze is scaled up by about its origin; 0: the smallest that fits "
        "the robot, as offline runs fit it (1 if it fits as it is); evorbc-sim and the launch "
        "file give the one the controller's task recorded",
        0.0,
        100.0,
    ),
    spec("robot", "4ws-5", "robot type (a registered robot)"),
    spec(
        "mode",
        "lockstep",
        "lockstep (deterministic, as fast as the graph) or realtime (10 Hz wall clock)",
        choices=("lockstep", "realtime"),
    ),
    spec("gui", False, "open the PyBullet window"),
    spec("start", "nominal", "start pose: nominal, random, or 'x,y,heading_deg'"),
    spec("seed", 0, "seed of a random start and of the perturbed world", 0, 2**32 - 1),
    spec(
        "perturb",
        "none",
        "perturbation or damage set for the simulated robot: none, a shipped set's name "
        "(config/perturbations) or a YAML file; one world drawn from the seed",
    ),
    spec(
        "episode_time",
        0.0,
        "episode length T (s); 0: the robot's own (120 for the 4WS robots)",
        0.0,
        1e6,
    ),
    spec(
        "lockstep_timeout",
        30.0,
        "wall seconds without commands before the state is sent again anyway",
        0.1,
        3600.0,
    ),
    spec(
        "wait_for_subscribers",
        ("scan", "odom"),
        "topics that need a subscriber before the run starts (a topic named k times: k "
        "subscribers, e.g. odom twice for an adapting arbitrator beside the radar node)",
    ),
    spec(
        "wait_for_publishers",
        (),
        "topics that need a publisher before the run starts; empty: the robot's command "
        "topics and evorbc/primitive",
    ),
    spec(
        "wait_for_ready",
        (),
        "latched std_msgs/Empty topics to hear on before the run starts (a recorder's "
        "recorder/ready, so that the bag holds the run from its first state)",
    ),
    spec(
        "startup_timeout",
        30.0,
        "wall seconds to wait for the graph (lockstep: then warn and wait on; realtime: "
        "start without what is missing)",
        0.1,
        3600.0,
    ),
    spec("result_file", "", "write the episode result here (JSON)"),
    spec("progress_period", 10.0, "simulated seconds between progress lines", 0.1, 1e6),
    spec("laser_beams", 360, "kinematic robots: laser beams per scan over 360 deg", 1, 100000),
    spec(
        "laser_range",
        2.0,
        "kinematic robots: laser range (m); evorbc-sim and the launch file raise it to the "
        "controller's rangefinder reach (mount radius + range) where that is farther",
        0.01,
        1000.0,
    ),
    spec(
        "wheel_radius",
        0.0,
        "4WS: wheel radius (m), as the executor's; 0: the robot's own",
        0.0,
        10.0,
    ),
    spec(
        "twist_stamped",
        True,
        "differential drive: cmd_vel is TwistStamped (false: Twist), as the executor's",
    ),
    *COMMON,
)

#: Topic-name parameters of earlier versions -> the topic to remap.
REMOVED = {
    "steering_topic": "steering_position_controller/commands",
    "wheel_topic": "wheel_velocity_controller/commands",
    "trajectory_topic": "joint_trajectory_controller/joint_trajectory",
    "cmd_vel_topic": "cmd_vel",
}
