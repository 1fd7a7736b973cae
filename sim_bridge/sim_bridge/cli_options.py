"""The options every program that picks a controller shares, each written once.

``evorbc-sim`` (here) and ``evorbc-evolve``'s ``arbitrator``, ``standard``, ``replay`` and
``evaluate`` (``offline_evolution``, a layer above, which imports this module) name the
controller, its repertoire, the robot and a seed the same way: one name, type, metavar,
default and help text per option. Where a program's own default differs (the shipped
controller, the file the arbitrator names), the caller says only that default.
"""

from __future__ import annotations

import argparse

from evorbc_ros.robots.registry import ROBOT_NAMES
from sim_bridge.cli_support import integer_in


def add_arbitrator(p: argparse.ArgumentParser, default: str | None = None) -> None:
    """``--arbitrator FILE``, the controller to run; required when ``default`` is None."""
    p.add_argument(
        "--arbitrator",
        metavar="FILE",
        required=default is None,
        help="arbitrator file" + (f" (default: {default})" if default else ""),
    )


def add_repertoire(p: argparse.ArgumentParser, default: str | None = None) -> None:
    """``--repertoire FILE``: an EvoRBC arbitrator's; required when ``default`` is None."""
    p.add_argument(
        "--repertoire",
        metavar="FILE",
        required=default is None,
        help=(
            f"repertoire of an EvoRBC arbitrator (default: {default})"
            if default
            else "repertoire file"
        ),
    )


def add_robot(
    p: argparse.ArgumentParser, help: str, default: str | None = None, required: bool = False
) -> None:
    """``--robot NAME``, one of the registered robots; ``help`` says what it picks."""
    p.add_argument("--robot", choices=ROBOT_NAMES, default=default, required=required, help=help)


#: The shared on/off options and their help.
FLAGS = {
    "--paper": "run the paper-protocol controller shipped for --robot (trained on the "
    "paper's mazes only) instead of its default one; not with --arbitrator",
    "--allow-mismatch": "use a repertoire (of the same robot) or sensor layout other than "
    "the one the arbitrator was evolved with",
}


def add_flag(p: argparse.ArgumentParser, name: str) -> None:
    """The on/off option ``name`` of :data:`FLAGS`."""
    p.add_argument(name, action="store_true", help=FLAGS[name])


def add_task(p: argparse.ArgumentParser, default: str) -> None:
    """``--task FILE.yaml``, the maze task settings (``default``: where they come from)."""
    p.add_argument("--task", metavar="FILE.yaml", help=f"maze task settings (default: {default})")


def add_seed(p: argparse.ArgumentParser, what: str) -> None:
    """``--seed N`` >= 0, default 0; ``what`` says what it draws in this program."""
    p.add_argument("--seed", type=integer_in(0), default=0, metavar="N", help=f"{what} (0)")
