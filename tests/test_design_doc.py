"""docs/design.md, the project's design record, has every section the repository cites.

Code, settings and docs cite it as "docs/design.md section N" (older text: "DESIGN.md
section N"); a reference may be split over two comment lines. Every cited number must be a
section of docs/design.md, and sections 1-11 keep the topics they have always had, so an old
reference still points at what it meant. Links to a section's anchor must match a heading.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "docs" / "design.md"

#: Folders that hold no project text (environments, caches, run outputs).
SKIP = {".git", ".venv", "venv", "build", "dist", "__pycache__", ".pytest_cache", "demo-output"}
SUFFIXES = {".py", ".md", ".yaml", ".yml", ".ini", ".toml", ".xml", ".txt", ".cfg", ".sh"}
NAMES = {"Makefile", "run"}  # .ci/run

#: "DESIGN.md section 4", "docs/design.md sections 2 and 3", also across a line break with a
#: comment marker ("DESIGN.md\n# section 4").
REFERENCE = re.compile(
    r"(?:docs/)?design\.md[\s#;*\"'`()]*sections?\s+(\d+(?:\s*(?:,|and|or|to|-)\s*\d+)*)",
    re.IGNORECASE,
)
ANCHOR = re.compile(r"design\.md#([\w-]+)", re.IGNORECASE)
HEADING = re.compile(r"^## (\d+)\. (.+)$", re.MULTILINE)

#: The topics of sections 1-11, cited by code since before docs/design.md existed.
TOPICS = {
    1: "conventions",
    2: "4ws",
    3: "quality",
    4: "maze",
    5: "sensors",
    6: "map-elites",
    7: "mapping",
    8: "neat",
    9: "ros 2 graph",
    10: "pypi",
    11: "hexapod",
}


def sections(text: str) -> dict[int, str]:
    """Section number -> title of the ``## N. Title`` headings."""
    return {int(n): title.strip() for n, title in HEADING.findall(text)}


def slug(title: str) -> str:
    """GitHub's anchor for a heading."""
    return re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


def cited(text: str) -> list[int]:
    """Every section number a text cites."""
    return [int(n) for group in REFERENCE.findall(text) for n in re.findall(r"\d+", group)]


def project_files():
    for folder, dirs, files in os.walk(ROOT):
        # Prune skipped folders before descending (the venv alone holds 100k files).
        dirs[:] = sorted(d for d in dirs if d not in SKIP and not d.endswith(".egg-info"))
        for name in sorted(files):
            path = Path(folder) / name
            if path == Path(__file__).resolve():
                continue  # its own examples of references
            if path.suffix in SUFFIXES or path.name in NAMES:
                yield path


@pytest.fixture(scope="module")
def record():
    return DESIGN.read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def references():
    """(file, section number) for every reference in the repository."""
    out = []
    for path in project_files():
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            continue
        out += [(path.relative_to(ROOT), n) for n in cited(text)]
    return out


def test_sections_are_numbered_in_order_and_keep_their_topics(record):
    found = sections(record)
    assert list(found) == list(range(1, len(found) + 1))
    for number, topic in TOPICS.items():
        assert topic in found[number].lower(), (number, found[number])


def test_every_reference_names_an_existing_section(record, references):
    found = sections(record)
    assert len(references) >= 20  # the scan sees the code's references
    missing = [f"{path}: section {n}" for path, n in references if n not in found]
    assert not missing, "references to sections docs/design.md does not have: " + "; ".join(missing)


def test_every_link_to_a_section_matches_a_heading(record):
    anchors = {slug(f"{n}. {title}") for n, title in sections(record).items()}
    anchors |= {slug(line.lstrip("# ")) for line in record.splitlines() if line.startswith("#")}
    broken = []
    for path in project_files():
        text = path.read_text(encoding="utf-8", errors="replace")
        broken += [
            f"{path.relative_to(ROOT)}: #{a}" for a in ANCHOR.findall(text) if a not in anchors
        ]
    assert not broken, broken


def test_references_are_found_in_both_spellings_and_across_lines():
    text = (
        "(paper Sec. IV-B, DESIGN.md\n# section 4)\n"
        '"""Motion model (docs/design.md section 2)."""\n'
        "see docs/design.md sections 12 and 13, or DESIGN.md section 99\n"
        "the design notes (no section) and section 5 of something else\n"
    )
    assert cited(text) == [4, 2, 12, 13, 99]


def test_a_missing_section_is_reported(record, tmp_path):
    found = sections(record)
    assert max(found) + 1 not in found
    assert [n for n in cited(f"DESIGN.md section {max(found) + 1}") if n not in found]


def test_no_reference_points_outside_the_repository():
    # The brief the project started from is not part of it: everything cites docs/design.md.
    bare = re.compile(r"(?<![\w/])DESIGN\.md")
    offenders = [
        str(path.relative_to(ROOT))
        for path in project_files()
        if bare.search(path.read_text(encoding="utf-8", errors="replace"))
    ]
    assert offenders == []
