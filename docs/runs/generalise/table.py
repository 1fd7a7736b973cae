"""Print the table of docs/generalisation.md from the finished runs here (markdown)."""

import json
import statistics
from pathlib import Path

HERE = Path(__file__).parent


def main() -> None:
    """Print one row per finished run."""
    print(
        "| run | training | paper mazes reached | held-out reached | held-out, `realistic` "
        "| held-out fitness | post-selection reached | s / generation |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for held in sorted(HERE.glob("*-seed*.held.json")):
        stem = held.name[: -len(".held.json")]
        paper = json.loads((HERE / f"{stem}.paper.json").read_text())["overall"]
        h = json.loads(held.read_text())["overall"]
        heldr = HERE / f"{stem}.heldr.json"
        r = (
            f"{json.loads(heldr.read_text())['overall']['reach_rate']:.1%}"
            if heldr.exists()
            else ""
        )
        data = json.loads((HERE / f"{stem}.arbitrator.json").read_text())
        arb = data["evolution"]
        training = arb["task"].get("training")
        what = "none (paper protocol)"
        if training:
            source = f"pool {training['pool']}" if training["pool"] else "fresh"
            what = f"K {training['generated']} x S {training['starts']}, {source}"
            if not training["task_mazes"]:
                what += ", no paper mazes"
            if training.get("perturb", "none") != "none":
                what += f", `{training['perturb']}`"
            if training.get("distance", "euclidean") != "euclidean":
                what += f", {training['distance']} fitness"
            if arb["task"]["samples_per_maze"] != 1:
                what += f", {arb['task']['samples_per_maze']} starts per paper maze"
        sensors = Path(arb["task"]["sensors"]).stem
        if sensors != "4ws":
            what += f", sensors {sensors}"
        if data["network"].get("recurrent"):
            what += ", recurrent"
        if arb["task"]["episode_time"] != 120.0:
            what += f", {arb['task']['episode_time']:g} s episodes"
        seconds = statistics.median(g["seconds"] for g in arb["history"])
        post = arb["post_evaluation"]
        print(
            f"| {stem} | {what} | {paper['reach_rate']:.0%} | **{h['reach_rate']:.1%}** | {r} | "
            f"{h['mean_fitness']:.3f} | {post['reached']:.0%} of {post['episodes_per_candidate']} "
            f"| {seconds:.2f} |"
        )


if __name__ == "__main__":
    main()
