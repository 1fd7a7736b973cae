"""docs/legged.md: the page the legged code cites gives every key its settings file takes.

The settings loader (``sim_bridge/legged/settings.py``) and the gait reader
(``evorbc_ros/robots/legged.py``) refuse a key they do not know; a key the page leaves out
is one a user cannot find. Every ``docs/*.md`` page the repository cites must exist.
"""

import dataclasses
import re
import subprocess

from evorbc_ros.config import config_dir
from sim_bridge.legged import settings as legged_settings

ROOT = config_dir().parent
PAGE = ROOT / "docs" / "legged.md"


def documented_keys() -> set[str]:
    """The keys in the first column of the page's settings table (``links.base`` etc.)."""
    return set(re.findall(r"^\| `([a-z_.]+)` \|", PAGE.read_text(), re.M))


def loader_keys() -> set[str]:
    keys = {f.name for f in dataclasses.fields(legged_settings._Top)}
    for section, cls in (
        ("links", legged_settings._Links),
        ("servo", legged_settings._Servo),
        ("physics", legged_settings._Physics),
        ("tilt", legged_settings._Tilt),
    ):
        keys |= {f"{section}.{f.name}" for f in dataclasses.fields(cls)}
    # The gait's keys (evorbc_ros.robots.legged.gait_from_settings) and the records.
    return keys | {"oscillators", "joints", "gait.frequency_hz", *legged_settings._RECORDS}


def test_the_legged_page_documents_every_settings_key():
    assert documented_keys() == loader_keys()


def test_every_docs_page_the_repository_cites_exists():
    files = subprocess.run(
        ["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split()
    cited = {}
    for name in files:
        if name.endswith((".py", ".yaml", ".md", ".ini", ".toml")):
            text = (ROOT / name).read_text(errors="replace")
            for page in re.findall(r"docs/[A-Za-z0-9_-]+\.md", text):
                cited.setdefault(page, name)
    missing = {page: by for page, by in cited.items() if not (ROOT / page).is_file()}
    assert missing == {}
