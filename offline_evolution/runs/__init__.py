"""Runs: the repertoire, arbitrator, replay and evaluation runs, as functions.

Each run takes a typed settings object (its command's options, one field each), does the
checks before any work, resolves its settings from the robot's files, resumes from its
checkpoint, and writes its outputs; it tells its progress through reporters
(:mod:`offline_evolution.reporters`) and prints nothing. ``evorbc-evolve`` parses
arguments and calls them with console reporters (:mod:`.terminal`, :mod:`.console`), a
recipe calls them in its process, a study in a worker process per step (:mod:`.worker`).
See docs/design.md section 20, "Runs".

* :func:`.repertoire.repertoire_run` (``RepertoireRun``): MAP-Elites.
* :func:`.arbitrator.arbitrator_run` (``ArbitratorRun``): NEAT, EvoRBC or standard.
* :func:`.replay.replay_run` (``ReplayRun``): a controller in its mazes.
* :func:`.evaluate.evaluate_run` (``EvaluateRun``): a controller on a suite of mazes.
"""
