"""The tutorials in docs/tutorials/ run as written: every ```python block of a tutorial, in order, in one namespace,
and every line of its ```bash blocks that starts with `freefloat` (run as `python -m freefloat ...`), all in an
empty temporary folder. A failure names the tutorial and the block."""

import re
import shlex
import subprocess
import sys
import traceback
from pathlib import Path

import pytest

TUTORIALS = sorted((Path(__file__).resolve().parent.parent / "docs" / "tutorials").glob("*.md"))
BLOCK = re.compile(r"^```(python|bash)\n(.*?)^```$", re.S | re.M)


def blocks(path: Path) -> list[tuple[int, str, str]]:
    """(number, language, code) of each python/bash block, numbered from 1 in document order."""
    return [(i, m.group(1), m.group(2)) for i, m in enumerate(BLOCK.finditer(path.read_text()), 1)]


def test_there_are_tutorials_with_code():
    assert TUTORIALS, "no docs/tutorials/*.md"
    for path in TUTORIALS:
        assert any(lang == "python" for _, lang, _ in blocks(path)), f"{path.name} has no python block"


@pytest.mark.parametrize("path", TUTORIALS, ids=[p.stem for p in TUTORIALS])
def test_tutorial_runs_as_written(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    ns: dict = {"__name__": "__tutorial__"}
    for number, lang, code in blocks(path):
        where = f"{path.name}, block {number} ({lang})"
        if lang == "python":
            try:
                exec(compile(code, where, "exec"), ns)
            except Exception:
                pytest.fail(f"{where} failed:\n{traceback.format_exc()}", pytrace=False)
            continue
        for line in code.splitlines():
            line = line.split(" #", 1)[0].strip()
            if not line.startswith("freefloat "):
                continue
            r = subprocess.run(
                [sys.executable, "-m", "freefloat", *shlex.split(line)[1:]], capture_output=True, text=True
            )
            if r.returncode != 0:
                pytest.fail(f"{where}: `{line}` exited {r.returncode}:\n{r.stdout}\n{r.stderr}", pytrace=False)
