"""Load every case of the corpus through the command line and classify what happened.

A worker process runs the commands one after another in-process (``evorbc-evolve`` and
``evorbc-study``'s ``main``), so a case costs its load, not a Python start-up. The worker
runs under an address-space limit, so a file that asks for more memory than that is met as
the MemoryError a smaller machine would see; a case that does not answer within the
timeout is a hang: the worker is killed and a new one takes the next case.

Outcomes:

* ``accepted``: status 0;
* ``refused``: a non-zero status with one line on stderr, ``PROG: error: ...``, naming one
  of the case's files;
* ``internal error``, ``traceback``, ``unnamed`` (a refusal naming none of its files),
  ``several lines``, ``hang``, ``crash`` (the worker died): failures, all of them.

Run ``python -P tests/fuzz/sweep.py --help`` (``make fuzz`` runs the whole corpus and
records the table in docs/fuzz.md).
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import io
import json
import os
import re
import select
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # `fuzz` is a package of the tests folder

from fuzz.corpus import Case, make_bases, mutants  # noqa: E402
from fuzz.hostile import named  # noqa: E402

#: Seconds a case may take before it counts as a hang (loads take well under one; an
#: accepted controller replays one short episode).
TIMEOUT = 60.0
#: The worker's address-space limit (bytes): far above any real load, far below the
#: 16 GiB a zip bomb asks for.
MEMORY = 6 << 30
FAILURES = ("internal error", "traceback", "unnamed", "several lines", "hang", "crash")


@dataclass
class Outcome:
    """What one case did: ``outcome`` (see the module), the message, seconds taken."""

    case: Case
    outcome: str
    message: str
    seconds: float

    @property
    def failed(self) -> bool:
        """Whether this outcome is a failure whatever the case expected."""
        return self.outcome in FAILURES or (
            self.case.expect is not None and self.outcome != self.case.expect
        )


# -- the worker -------------------------------------------------------------------------------


def _serve() -> None:
    """Worker: read one JSON request per line, run it, answer one JSON line."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))
    from offline_evolution.cli import main as evolve_main
    from offline_evolution.study.cli import main as study_main

    mains = {"evorbc-evolve": evolve_main, "evorbc-study": study_main}
    answer = os.fdopen(os.dup(1), "w")
    for line in sys.stdin:
        request = json.loads(line)
        err = io.StringIO()
        saved = {k: os.environ.get(k) for k in request["env"]}
        os.environ.update(request["env"])
        try:
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                code = mains[request["program"]](request["argv"])
        except SystemExit as e:  # argparse
            code = e.code if isinstance(e.code, int) else 1
        except BaseException as e:  # a failure to report, not to hide
            code, err = 99, io.StringIO(f"Traceback (uncaught {type(e).__name__}: {e})\n")
        finally:
            for k, v in saved.items():
                os.environ.pop(k, None) if v is None else os.environ.__setitem__(k, v)
        text = err.getvalue().encode("utf-8", "backslashreplace").decode()
        answer.write(json.dumps({"code": code, "err": text}) + "\n")
        answer.flush()


class Worker:
    """A worker process, restarted after a hang or a crash."""

    def __init__(self) -> None:
        self.process: subprocess.Popen | None = None

    def run(self, request: dict, timeout: float) -> dict | str:
        """The worker's answer, or ``"hang"`` / ``"crash"``."""
        if self.process is None or self.process.poll() is not None:
            self.process = subprocess.Popen(
                [sys.executable, "-P", __file__, "--serve"],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
                env={**os.environ, "PYTHONSAFEPATH": "1"},
            )
        p = self.process
        p.stdin.write(json.dumps(request) + "\n")
        p.stdin.flush()
        ready, _, _ = select.select([p.stdout], [], [], timeout)
        if not ready:
            self.stop()
            return "hang"
        line = p.stdout.readline()
        if not line:
            self.stop()
            return "crash"
        return json.loads(line)

    def stop(self) -> None:
        """Kill the worker (a new one starts with the next case)."""
        if self.process is not None:
            self.process.kill()
            self.process.wait()
            self.process = None


# -- running cases -----------------------------------------------------------------------------


def _place(text: str, folder: Path, bases: Path) -> str:
    return text.replace("{dir}", str(folder)).replace("{base}", str(bases))


def materialise(case: Case, folder: Path, bases: Path) -> list[str]:
    """Write ``case``'s files into ``folder``; its command line."""
    folder.mkdir(parents=True)
    for name, content in case.files.items():
        path = folder / name
        if callable(content):
            content(path)
        else:
            if isinstance(content, str):
                content = content.encode("utf-8", "surrogatepass")
            if name.endswith((".yaml", ".json")) and b"{dir}" in content[:100_000]:
                content = _place(content.decode("utf-8", "surrogatepass"), folder, bases).encode(
                    "utf-8", "surrogatepass"
                )
            path.write_bytes(content)
    return [_place(a, folder, bases) for a in case.argv]


def classify(case: Case, answer: dict | str, folder: Path) -> tuple[str, str]:
    """(outcome, message) of one case's answer."""
    if isinstance(answer, str):
        return answer, ""
    err = answer["err"].strip()
    if answer["code"] == 0:
        return "accepted", ""
    if "Traceback" in err:
        return "traceback", err[-300:]
    if "internal error" in err:
        return "internal error", err
    lines = [line for line in err.splitlines() if line.strip()]
    if len(lines) != 1:
        return "several lines", err[:300]
    if str(folder) not in err:
        return "unnamed", err
    return "refused", err


def run_cases(cases, bases: Path, work: Path, timeout: float = TIMEOUT, progress=None):
    """Run ``cases``; one :class:`Outcome` each, in order."""
    worker = Worker()
    outcomes = []
    try:
        for i, case in enumerate(cases):
            folder = work / f"{i:05d}"
            argv = materialise(case, folder, bases)
            request = {"program": case.program, "argv": argv, "env": case.env}
            start = time.perf_counter()
            answer = worker.run(request, timeout)
            seconds = time.perf_counter() - start
            outcome, message = classify(case, answer, folder)
            outcomes.append(Outcome(case, outcome, message.replace(str(folder), "DIR"), seconds))
            shutil.rmtree(folder, ignore_errors=True)
            if progress:
                progress(outcomes[-1])
    finally:
        worker.stop()
    return outcomes


def corpus(bases: Path, seed: int, per_kind: int, big: bool) -> list[Case]:
    """The named cases and ``per_kind`` mutants of each format from ``seed``."""
    return [*named(bases, big), *mutants(bases, seed, per_kind)]


# -- the record ------------------------------------------------------------------------------------


def _reason(message: str) -> str:
    """The gist of a refusal: the message without its program, paths and numbers."""
    text = re.sub(r"^[\w-]+( [\w-]+)?: error: ", "", message)
    text = re.sub(r"\S*DIR\S*", "FILE", text)
    text = re.sub(r"-?\d[\d,._e+-]*", "N", text)
    return text[:90]


def table(outcomes: list[Outcome]) -> str:
    """A Markdown record: cases by family and outcome, and the refusals' reasons."""
    families = collections.Counter()
    by_outcome = collections.defaultdict(collections.Counter)
    for o in outcomes:
        family = o.case.name.split("/")[0] + " " + o.case.kind
        families[family] += 1
        by_outcome[family][o.outcome] += 1
    columns = ["accepted", "refused", *FAILURES]
    lines = [
        "| family | format | cases | " + " | ".join(columns) + " |",
        "|---|---|---:|" + "---:|" * len(columns),
    ]
    for family in sorted(families):
        kind, fmt = family.split(" ")
        counts = by_outcome[family]
        cells = " | ".join(str(counts.get(c, 0)) for c in columns)
        lines.append(f"| {kind} | {fmt} | {families[family]} | {cells} |")
    total = collections.Counter(o.outcome for o in outcomes)
    cells = " | ".join(str(total.get(c, 0)) for c in columns)
    lines.append(f"| **all** | | **{len(outcomes)}** | {cells} |")
    reasons = collections.Counter(_reason(o.message) for o in outcomes if o.outcome == "refused")
    lines += ["", "Most common reasons for refusal:", ""]
    lines += [f"- {n} x `{r}`" for r, n in reasons.most_common(25)]
    accepted = [o for o in outcomes if o.outcome == "accepted" and o.case.what]
    lines += ["", "Mutants accepted, and what they changed (the change was harmless):", ""]
    lines += [f"- `{o.case.name}`: {o.case.what}" for o in accepted[:40]]
    return "\n".join(lines) + "\n"


RECORD_HEAD = """# The fuzz corpus: what evorbc does with hostile and broken files

Made by `make fuzz` (`tests/fuzz/sweep.py --big --per-kind 100 --record docs/fuzz.md`) on
{machine}. Every case is a file set and the command line that loads it, run through
`evorbc-evolve` or `evorbc-study` as a user would (docs/design.md section 12). *Named*
cases are hostile or careless files that must be refused; *mutants* are valid files
changed at random from a seed, which may be accepted or refused. A failure is a hang (no
answer in 60 s), a crash, an internal error, a traceback, several lines, or a refusal that
names none of the case's files. The suite runs a fast subset (tests/test_fuzz.py).

"""


def _machine() -> str:
    import platform

    day = time.strftime("%Y-%m-%d")
    return f"{os.cpu_count()} cores, Python {platform.python_version()}, {day}"


def main(argv=None) -> int:
    """Run the corpus, print the table, and optionally write it to a Markdown file."""
    p = argparse.ArgumentParser(prog="sweep.py", description=__doc__.splitlines()[0])
    p.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--seed", type=int, default=0, help="mutants' seed (0)")
    p.add_argument("--per-kind", type=int, default=60, help="mutants per format (60)")
    p.add_argument("--big", action="store_true", help="the full-size big files too")
    p.add_argument("--only", help="run only cases whose name contains this")
    p.add_argument("--record", metavar="FILE.md", help="write the table to this file")
    args = p.parse_args(argv)
    if args.serve:
        _serve()
        return 0
    with tempfile.TemporaryDirectory(prefix="evorbc-fuzz-") as tmp:
        bases = Path(tmp) / "bases"
        with contextlib.redirect_stdout(io.StringIO()):
            make_bases(bases)
        cases = corpus(bases, args.seed, args.per_kind, args.big)
        if args.only:
            cases = [c for c in cases if args.only in c.name]
        start = time.perf_counter()

        def progress(o: Outcome) -> None:
            mark = "FAIL" if o.failed else "ok"
            print(f"{mark:4} {o.outcome:14} {o.seconds:6.2f} s  {o.case.name}  {o.message[:120]}",
                  file=sys.stderr, flush=True)  # fmt: skip

        outcomes = run_cases(cases, bases, Path(tmp) / "cases", progress=progress)
        elapsed = time.perf_counter() - start
    text = table(outcomes)
    failed = [o for o in outcomes if o.failed]
    slowest = max(outcomes, key=lambda o: o.seconds)
    summary = (
        f"{len(outcomes)} cases (seed {args.seed}, {args.per_kind} mutants per format"
        f"{', big files at full size' if args.big else ''}) in {elapsed:.0f} s; "
        f"{len(failed)} failed; slowest {slowest.seconds:.1f} s ({slowest.case.name})"
    )
    print(text + "\n" + summary)
    if args.record:
        head = RECORD_HEAD.format(machine=_machine())
        Path(args.record).write_text(f"{head}{text}\n{summary}\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
