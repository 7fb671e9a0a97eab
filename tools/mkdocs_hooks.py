"""mkdocs hooks (mkdocs.yml `hooks:`): the repository files the docs pages link to from outside docs/.

The docs/*.md pages are written to read on GitHub, so they link to `../BENCHMARKS.md` and to figures under
`../benches/results/`. mkdocs only publishes files under docs/; this hook adds those files to the site (the
benchmark report as a page, the figures as assets) and points the pages' links at them. The pages themselves are
not changed.
"""

from __future__ import annotations

import re
from pathlib import Path

from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parent.parent
# repository file -> its path in the site (relative to docs/)
OUTSIDE = {
    "BENCHMARKS.md": "benchmarks.md",
    "benches/results/soak.png": "assets/soak.png",
}


def on_files(files: Files, config) -> Files:
    for src, dest in OUTSIDE.items():
        files.append(File.generated(config, dest, abs_src_path=str(ROOT / src)))
    return files


def on_page_markdown(markdown: str, page, config, files) -> str:
    depth = page.file.src_uri.count("/")  # folders between docs/ and the page
    up = "../" * (depth + 1)  # from the page to the repository root
    down = "../" * depth  # from the page to docs/
    for src, dest in OUTSIDE.items():
        markdown = re.sub(r"\]\(" + re.escape(up + src), "](" + down + dest, markdown)
    return markdown
