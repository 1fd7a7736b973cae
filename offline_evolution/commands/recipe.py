"""``evorbc-evolve recipe``: make a shipped controller from its recipe file."""

from __future__ import annotations

import argparse
from pathlib import Path

from offline_evolution.commands.common import add_workers_option, count
from offline_evolution.runs.errors import UserError


def add_parsers(sub) -> None:
    """Register ``recipe``."""
    from offline_evolution.recipes.budget import BUDGETS

    p = sub.add_parser(
        "recipe",
        help="run a recipe (config/recipes/*.yaml): every step that makes a shipped controller",
        description="Run a recipe's steps in order (repertoire, arbitrator, warm start, "
        "copy) in one output folder. Run it again to resume: finished steps are skipped and "
        "an interrupted one continues from its checkpoint. At the full budget each output "
        "is compared with the shipped file the recipe states (docs/design.md, 'Recipes').",
    )
    p.add_argument("recipe", metavar="RECIPE.yaml", help="recipe file")
    p.add_argument(
        "--out",
        metavar="DIR",
        help="output folder (default: recipe-runs/NAME-BUDGET in the current folder)",
    )
    p.add_argument(
        "--budget",
        choices=BUDGETS,
        default="full",
        help="full: the recipe as written (hours for the legged robots); small: every step "
        "on a tiny budget, to check the recipe in seconds (full)",
    )
    p.add_argument("--quiet", action="store_true", help="no per-generation or per-batch lines")
    add_workers_option(p)
    p.set_defaults(func=cmd_recipe)

    p = sub.add_parser(
        "from-robot",
        help="from a URDF or a robot settings file to a controller, at a profile's budgets",
        description="Write the recipe of a profile (config/profiles/*.yaml) for a robot and "
        "run it in one output folder: for a URDF, robot-from-urdf, design-gait, repertoire "
        "and arbitrator; for a robot settings file, repertoire and arbitrator. Run it again "
        "to resume (docs/your-robot.md, 'The quick path').",
    )
    p.add_argument(
        "source",
        metavar="URDF|ROBOT.yaml",
        help="a URDF (or pybullet_data:PATH) or a robot settings file",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument(
        "--profile",
        choices=("quick", "full"),
        default="quick",
        help="quick: about an hour on 2 cores; full: the paper's budgets (quick)",
    )
    p.add_argument("--seed", type=count, default=1, help="seed of every step (default 1)")
    p.add_argument("--name", help="a URDF robot's name (default: the URDF's stem + '-urdf')")
    p.add_argument(
        "--budget",
        choices=BUDGETS,
        default="full",
        help="small: every step on a tiny budget, to check the path (full)",
    )
    p.add_argument("--quiet", action="store_true", help="no per-generation or per-batch lines")
    add_workers_option(p)
    p.set_defaults(func=cmd_from_robot)


def cmd_from_robot(args: argparse.Namespace) -> int:
    """Write the profile's recipe for the robot and run it; 0 when every step is done."""
    from offline_evolution.recipes.profiles import write_profile_recipe
    from offline_evolution.recipes.runner import run_recipe
    from offline_evolution.recipes.spec import load_recipe

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out} is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    path = write_profile_recipe(args.source, args.profile, out, args.seed, args.name)
    recipe = load_recipe(path)
    outcomes = run_recipe(recipe, out, args.budget, args.workers, args.quiet)
    controller = outcomes[-1].out
    print(f"{recipe.recipe}: {len(outcomes)} steps done -> {controller}")
    return 0


def cmd_recipe(args: argparse.Namespace) -> int:
    """Run the recipe; 0 when every step is done and, at the full budget, known; else 1."""
    from offline_evolution.recipes.runner import run_recipe
    from offline_evolution.recipes.spec import load_recipe

    recipe = load_recipe(args.recipe)
    name = Path(args.recipe).name.removesuffix(".yaml").removesuffix(".yml")
    out = Path(args.out) if args.out else Path("recipe-runs") / f"{name}-{args.budget}"
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {out} is not a folder")
    outcomes = run_recipe(recipe, out, args.budget, args.workers, args.quiet)
    unknown = [o.step for o in outcomes if o.verdict is not None and not o.verdict.known]
    if unknown:
        print(f"{recipe.recipe}: {', '.join(unknown)} not the file the recipe states -> {out}")
        return 1
    done = "reproduced or known" if args.budget == "full" else "done at the small budget"
    print(f"{recipe.recipe}: {len(outcomes)} steps {done} -> {out}")
    return 0
