"""Onboard adaptation: a corrected outcome model of the repertoire (docs/design.md section 24).

:mod:`~evorbc_ros.adaptation.gp` and :mod:`~evorbc_ros.adaptation.motion` are plain
functions the offline kernels can compile with numba; :mod:`~evorbc_ros.adaptation.model`
keeps the model's arrays and :mod:`~evorbc_ros.adaptation.online` feeds it from odometry.
"""

from evorbc_ros.adaptation.model import (
    AdaptationSettings,
    OutcomeModel,
    outcome_table,
    settings_for,
)
from evorbc_ros.adaptation.online import OnlineAdaptation, adapted_choice

__all__ = [
    "AdaptationSettings",
    "OnlineAdaptation",
    "OutcomeModel",
    "adapted_choice",
    "outcome_table",
    "settings_for",
]
