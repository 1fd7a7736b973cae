"""MAP-Elites: archive layout, the paper's mutation, determinism, checkpoints and resume."""

import numpy as np
import pytest
from conftest import small_settings

from evorbc_ros.robots.hexapod import SERVO_RATE
from offline_evolution.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
from offline_evolution.repertoire.archive import cvt_layout, grid_layout, make_archive
from offline_evolution.repertoire.emitter import IsoLineDDEmitter, PaperMutationEmitter
from offline_evolution.repertoire.map_elites import (
    Interrupted,
    MapElites,
    generate_repertoire,
)
from offline_evolution.repertoire.settings import load_settings


def assert_same_repertoire(a, b):
    for field in ("genes", "behaviour", "heading", "quality"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field))


def test_grid_is_symmetric_with_a_cell_centred_on_the_origin():
    layout = grid_layout(max_reach=0.4, bin_size=0.04)
    assert layout["dims"] == [21, 21]
    np.testing.assert_allclose(layout["low"], [-0.42, -0.42])
    np.testing.assert_allclose(layout["high"], [0.42, 0.42])
    archive = make_archive(layout, solution_dim=2, seed=0)
    centre = archive.index_of(np.array([[0.0, 0.0], [0.019, -0.019]]))
    assert centre[0] == centre[1] == archive.grid_to_int_index([[10, 10]])[0]
    mirrored = archive.index_of(np.array([[0.11, 0.29], [-0.11, -0.29]]))
    grid = archive.int_to_grid_index(mirrored)
    assert tuple(grid[0] + grid[1]) == (20, 20)


def test_a_cell_only_takes_a_strictly_better_primitive():
    archive = make_archive(grid_layout(0.4, 0.04), solution_dim=1, seed=0)
    where = np.array([[0.1, 0.1]])
    archive.add(np.array([[0.1]]), np.array([0.5]), where, heading=np.array([0.0]))
    archive.add(np.array([[0.2]]), np.array([0.5]), where, heading=np.array([0.0]))
    assert archive.data("solution")[0, 0] == 0.1
    archive.add(np.array([[0.3]]), np.array([0.6]), where, heading=np.array([0.0]))
    assert archive.data("solution")[0, 0] == 0.3


def test_paper_mutation_changes_a_quarter_of_the_genes_by_half_a_unit():
    archive = make_archive(grid_layout(0.4, 0.04), solution_dim=5, seed=0)
    archive.add(np.zeros((1, 5)), np.ones(1), np.zeros((1, 2)), heading=np.zeros(1))
    emitter = PaperMutationEmitter(
        archive, initial_batch=10, batch_size=40000, mutation_probability=0.25, sigma=0.5, seed=1
    )
    first = emitter.ask()
    assert first.shape == (10, 5) and np.all(np.abs(first) <= 1)
    assert np.all(first != 0.0)  # random, not mutants of the one elite
    mutants = emitter.ask()
    assert mutants.shape == (40000, 5)
    changed = mutants != 0.0
    assert changed.mean() == pytest.approx(0.25, abs=0.01)
    assert np.all(np.abs(mutants) <= 1.0)
    # N(0, 0.5) clipped to [-1, 1]: inside, a normal truncated at 2 sd (sd 0.44 m).
    inner = mutants[changed & (np.abs(mutants) < 1.0)]
    assert np.std(inner) == pytest.approx(0.4398, abs=0.01)
    assert np.mean(np.abs(mutants[changed]) == 1.0) == pytest.approx(0.0455, abs=0.01)


def test_initial_batch_comes_in_pieces_drawn_as_one_batch():
    archive = make_archive(grid_layout(0.4, 0.04), solution_dim=3, seed=0)
    emitter = PaperMutationEmitter(
        archive, initial_batch=250, batch_size=100, mutation_probability=0.25, sigma=0.5, seed=4
    )
    pieces = [emitter.ask() for _ in range(3)]
    assert [len(p) for p in pieces] == [100, 100, 50]
    whole = np.random.default_rng(4).uniform(-1.0, 1.0, size=(250, 3))
    np.testing.assert_array_equal(np.concatenate(pieces), whole)
    # Nothing in the archive after the initial batch: more random solutions, not mutants.
    assert emitter.ask().shape == (100, 3)


def test_behaviours_outside_the_archive_are_dropped_not_clipped():
    from sim_bridge.robots.base import PrimitiveOutcome

    run = MapElites(small_settings())
    edge = run.layout["high"][0]
    outcome = PrimitiveOutcome(
        x=np.array([0.1, edge + 0.01]),
        y=np.array([0.0, 0.0]),
        heading=np.zeros(2),
        path=np.array([0.1, edge]),
    )
    run.tell(np.zeros((2, 5)), outcome)
    assert len(run.archive) == 1 and run.discarded == 1


def test_same_seed_same_repertoire_and_other_seed_differs(small_repertoire):
    assert_same_repertoire(small_repertoire, generate_repertoire(small_settings()))
    other = generate_repertoire(small_settings(seed=8))
    assert not np.array_equal(
        other.genes[: len(small_repertoire)], small_repertoire.genes[: len(other)]
    )


@pytest.mark.parametrize("stop_at_batch, iteration", [(2, 0), (16, 12)])
def test_resumed_run_equals_an_uninterrupted_run(
    tmp_path, small_repertoire, stop_at_batch, iteration
):
    # The initial batch of 400 comes in 4 pieces of the batch size (100): batch 2 is
    # inside it, batch 16 is iteration 12.
    ckpt = tmp_path / "run.checkpoint.npz"
    polls = []

    def stop():
        polls.append(1)
        return len(polls) == stop_at_batch

    with pytest.raises(Interrupted) as info:
        generate_repertoire(small_settings(), checkpoint=ckpt, checkpoint_every=5, should_stop=stop)
    assert info.value.iteration == iteration and ckpt.exists()
    seen = []
    resumed = generate_repertoire(
        small_settings(), checkpoint=ckpt, checkpoint_every=5, progress=seen.append
    )
    assert seen[0].resumed_from == iteration
    assert seen[0].evaluations == 100 * (stop_at_batch + 1)
    assert resumed.algorithm["evaluations"] == small_settings().evaluations
    assert_same_repertoire(resumed, small_repertoire)
    assert not ckpt.exists()  # a finished run removes its checkpoint


def test_resume_from_a_periodic_checkpoint_after_a_crash(tmp_path, small_repertoire):
    ckpt = tmp_path / "run.ckpt.npz"
    run = MapElites(small_settings())
    for _ in range(10):
        run.step()
    run.save(ckpt)
    for _ in range(3):
        run.step()  # work after the last checkpoint is lost in a crash, then redone
    resumed = generate_repertoire(small_settings(), checkpoint=ckpt)
    assert_same_repertoire(resumed, small_repertoire)


def test_checkpoint_of_another_run_is_refused(tmp_path):
    ckpt = tmp_path / "c.npz"
    run = MapElites(small_settings())
    run.step()
    run.save(ckpt)
    with pytest.raises(CheckpointError, match="seed is 7 in the checkpoint but 9 now"):
        generate_repertoire(small_settings(seed=9), checkpoint=ckpt)
    ckpt.write_bytes(ckpt.read_bytes()[:100])
    with pytest.raises(CheckpointError, match="not a checkpoint"):
        generate_repertoire(small_settings(), checkpoint=ckpt)


def test_checkpoint_for_another_robot_design_is_refused(tmp_path):
    ckpt = tmp_path / "c.npz"
    run = MapElites(small_settings())
    run.step()
    run.save(ckpt)
    header, arrays = load_checkpoint(ckpt)
    header["simulation"] = {"geometry": {"tibia_length": 0.14}}
    save_checkpoint(ckpt, header, arrays)
    with pytest.raises(CheckpointError, match=r"different robot .*simulation is"):
        generate_repertoire(small_settings(), checkpoint=ckpt)


def test_repertoire_carries_its_settings_and_summary(small_repertoire):
    r = small_repertoire
    assert r.robot == "4ws-5" and r.metric == "circular" and r.seed == 7
    assert r.eval_time == 2.0 and r.bin_size == 0.04
    assert r.algorithm["evaluations"] == 400 + 25 * 100
    assert [p.name for p in r.parameters] == [
        "speed",
        "angle_fl",
        "angle_fr",
        "angle_rl",
        "angle_rr",
    ]
    s = r.summary()
    assert s["count"] == len(r) > 50
    assert s["qd_score"] == pytest.approx(r.quality.sum())
    # One primitive per cell.
    cells = np.floor((r.behaviour - np.array(r.archive["low"])) / r.bin_size).astype(int)
    assert len({tuple(c) for c in cells}) == len(r)


@pytest.mark.slow
def test_full_table_one_budget_gives_a_high_quality_4ws5_repertoire():
    # Paper Sec. IV-D: "MAP-Elites is able to evolve high-quality repertoires" (1.01M evals).
    r = generate_repertoire(load_settings(robot="4ws-5", seed=1))
    s = r.summary()
    assert r.algorithm["evaluations"] == 1_010_000
    assert s["mean_quality"] > 0.95
    assert s["count"] > 230
    # A 4WS robot moves as far left as right and as far backward as forward.
    x, y = r.behaviour.T
    assert abs(np.sum(y > 0) - np.sum(y < 0)) < 0.1 * len(r)
    assert abs(np.sum(x > 0) - np.sum(x < 0)) < 0.1 * len(r)


def test_iso_line_dd_children_lie_near_the_line_through_two_elites():
    archive = make_archive(grid_layout(0.4, 0.04), solution_dim=4, seed=0)
    a, b = np.array([-0.5, 0.0, 0.2, 0.4]), np.array([0.5, 0.0, -0.2, 0.4])
    archive.add(np.array([a, b]), np.ones(2), np.array([[0.1, 0.0], [-0.1, 0.0]]),
                heading=np.zeros(2))  # fmt: skip
    emitter = IsoLineDDEmitter(
        archive, initial_batch=1, batch_size=20000, iso_sigma=0.02, line_sigma=0.2, seed=3
    )
    emitter.ask()  # the random first batch
    children = emitter.ask()
    # Each child is a parent plus N(0, 0.02) per gene plus N(0, 0.2) times the difference
    # of two parents (zero when both are the same elite, half the time).
    off_line = children[:, [1, 3]] - (0.0, 0.4)  # genes where a and b agree
    assert np.std(off_line) == pytest.approx(0.02, rel=0.05)
    along = children[:, 0]
    assert np.all(np.abs(along) <= 1.0)
    near_parent = np.minimum(np.abs(along - 0.5), np.abs(along + 0.5))
    assert np.mean(near_parent < 0.06) == pytest.approx(0.5 + 0.5 * 0.23, abs=0.03)


@pytest.mark.slow
def test_cvt_archive_is_mirror_symmetric_with_as_many_cells_as_the_grid():
    layout = cvt_layout(max_reach=0.4, bin_size=0.04, seed=2)
    assert layout["cells"] == 21 * 21 - 1 and layout["low"] == grid_layout(0.4, 0.04)["low"]
    centroids = np.array(layout["centroids"])
    mirrored = centroids * (1.0, -1.0)
    archive = make_archive(layout, solution_dim=1, seed=0)
    points = np.random.default_rng(0).uniform(-0.42, 0.42, size=(2000, 2))
    cells = archive.index_of(points)
    mirror_cells = archive.index_of(points * (1.0, -1.0))
    # the cell of a mirrored point is the mirror of the point's cell
    np.testing.assert_allclose(centroids[mirror_cells], mirrored[cells], atol=1e-12)
    assert layout == cvt_layout(max_reach=0.4, bin_size=0.04, seed=2)  # seeded


@pytest.mark.slow
@pytest.mark.parametrize(
    "archive, variation", [("grid", "iso_line_dd"), ("cvt", "paper"), ("cvt", "iso_line_dd")]
)
def test_other_operators_and_archives_resume_exactly(tmp_path, archive, variation):
    settings = small_settings(archive=archive, variation=variation, iterations=10)
    whole = generate_repertoire(settings)
    assert whole.archive["kind"] == archive and whole.algorithm["variation"] == variation
    assert len(whole) > 50
    ckpt = tmp_path / "run.checkpoint.npz"
    polls = []
    with pytest.raises(Interrupted):
        generate_repertoire(
            settings, checkpoint=ckpt, should_stop=lambda: polls.append(1) or len(polls) == 7
        )
    assert_same_repertoire(generate_repertoire(settings, checkpoint=ckpt), whole)


def test_symmetry_counts_filled_cells_whose_mirror_cell_is_filled(small_repertoire):
    import dataclasses

    from offline_evolution.repertoire.stats import repertoire_stats

    behaviour = np.array([[0.0, 0.0], [0.09, 0.2], [0.09, -0.2], [0.31, 0.12], [0.31, 0.13]])
    rep = dataclasses.replace(
        small_repertoire,
        genes=small_repertoire.genes[:5],
        behaviour=behaviour,
        heading=np.zeros(5),
        quality=np.array([1.0, 1.5, 1.5, 1.2, 1.0]),
        # Qualities up to 2 and two primitives in one 4 cm cell: no archive (whose cells
        # hold one each) and a metric whose range is [0, 2].
        metric="distance+circular",
        archive={},
    )
    s = repertoire_stats(rep, bin_size=0.04)
    # cells (0, 0), (2, 5), (2, -5), (8, 3): 3 off the x axis, 2 of them mirrored
    assert s["count"] == 5 and s["cells"] == 4
    assert s["mirrored"] == pytest.approx(2 / 3)
    assert (s["left"], s["right"]) == (3, 1)
    assert s["qd_score"] == pytest.approx(6.2)


def test_hexapod_run_resumes_to_the_uninterrupted_result(tmp_path):
    settings = load_settings(robot="hexapod", initial_batch=40, batch_size=20, iterations=3, seed=2)
    whole = generate_repertoire(settings, workers=1)
    assert whole.robot == "hexapod" and len(whole) > 10
    assert whole.algorithm["simulation"]["physics"]["rate_hz"] == SERVO_RATE
    ckpt = tmp_path / "hexapod.checkpoint.npz"
    polls = []
    with pytest.raises(Interrupted):
        generate_repertoire(
            settings,
            checkpoint=ckpt,
            workers=1,
            should_stop=lambda: polls.append(1) or len(polls) == 3,  # inside iteration 1
        )
    assert_same_repertoire(generate_repertoire(settings, checkpoint=ckpt, workers=1), whole)
