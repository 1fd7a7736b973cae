"""docs/design.md, the project's design record, has every section the repository cites.

Code, settings and docs cite it as "docs/design.md section N" (older text: "DESIGN.md
section N"); a reference may be split over two comment lines. Every cited number must be a
section of docs/design.md, and sections 1-11 keep the topics they have always had, so an old
reference still points at what it meant. Links to a section's anchor must match a heading.

docs/design.md is the index: each numbered section links to the focused page under
docs/design/ that holds its full text. Every relative link in the index and the pages
resolves to a file, and to a heading where it names one; the pages say how things are, so
none holds a diary marker (a date, "this session", "until 2026"): history is CHANGELOG.md's.
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "docs" / "design.md"
PAGES = ROOT / "docs" / "design"

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
#: A Markdown link's target: [text](target), not an image's or a web address's.
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)")
#: Text that narrates history rather than saying how things are.
DIARY = re.compile(
    r"\b20\d\d-\d\d-\d\d\b|\bthis session\b|\buntil 20\d\d\b|\bissue \d+\b"
    r"|\bbefore the change\b|\bas before\b",
    re.IGNORECASE,
)

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


def record_files() -> list[Path]:
    """docs/design.md and its pages."""
    return [DESIGN, *sorted(PAGES.glob("*.md"))]


def heading_anchors(text: str) -> set[str]:
    """GitHub's anchors for the headings of a Markdown text (outside code blocks)."""
    anchors: set[str] = set()
    fenced = False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced
        match = None if fenced else re.match(r"^#{1,6} (.+?)\s*$", line)
        if match:
            base = slug(match.group(1))
            anchor, n = base, 0
            while anchor in anchors:  # GitHub numbers repeated headings
                n += 1
                anchor = f"{base}-{n}"
            anchors.add(anchor)
    return anchors


def broken_links(path: Path) -> list[str]:
    """The relative links of a Markdown file that name no file, or no heading of it."""
    broken = []
    for target in LINK.findall(path.read_text(encoding="utf-8")):
        if re.match(r"^[a-z]+:", target):
            continue  # https:, mailto:
        name, _, anchor = target.partition("#")
        linked = (path.parent / name).resolve() if name else path
        if not linked.exists():
            broken.append(f"{path.relative_to(ROOT)}: {target} (no such file)")
        elif (
            anchor
            and linked.suffix == ".md"
            and anchor not in heading_anchors(linked.read_text(encoding="utf-8"))
        ):
            broken.append(f"{path.relative_to(ROOT)}: {target} (no such heading)")
    return broken


def test_each_section_links_to_its_page(record):
    bodies = re.split(r"^## \d+\. .+$", record, flags=re.MULTILINE)[1:]
    assert len(bodies) == len(sections(record))
    for (number, title), body in zip(sections(record).items(), bodies, strict=True):
        pages = [t for t in LINK.findall(body) if t.startswith("design/")]
        assert pages, f"section {number} ({title}) links to no page under docs/design/"
        for target in pages:
            assert (DESIGN.parent / target.partition("#")[0]).is_file(), (number, target)


def test_every_page_is_reached_from_the_index(record):
    linked = {t.partition("#")[0] for t in LINK.findall(record) if t.startswith("design/")}
    pages = {f"design/{p.name}" for p in PAGES.glob("*.md")}
    assert pages, "docs/design/ holds no pages"
    assert pages <= linked, f"pages the index does not link: {sorted(pages - linked)}"


def test_every_relative_link_of_the_record_resolves():
    broken = [line for path in record_files() for line in broken_links(path)]
    assert not broken, broken


def test_a_broken_link_and_a_missing_heading_are_reported(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "a.md").write_text("# Title\n\n## Some `code`: here\n\n## Some code here\n")
    page = tmp_path / "b.md"
    page.write_text(
        "[ok](a.md#some-code-here) [twice](a.md#some-code-here-1) [web](https://x.org/y)\n"
        "[gone](c.md) [wrong](a.md#nothing) [self](#title)\n"
    )
    assert broken_links(page) == [
        "b.md: c.md (no such file)",
        "b.md: a.md#nothing (no such heading)",
        "b.md: #title (no such heading)",
    ]


def test_no_page_of_the_record_is_a_diary():
    found = [
        f"{path.relative_to(ROOT)}:{n}: {line.strip()}"
        for path in record_files()
        for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if DIARY.search(line)
    ]
    assert not found, "history belongs in CHANGELOG.md: " + "; ".join(found)


def test_diary_markers_are_recognised():
    diary = [
        "Until 2026-11-26 they did not.",
        "made before this session",
        "until 2026 the grid was brute force",
        "issue 21 changed the task",
        "the same speed as before",
    ]
    assert all(DIARY.search(text) for text in diary)
    current = ["a run resumes until the last generation", "an issue of taste", "before the run"]
    assert not any(DIARY.search(text) for text in current)
