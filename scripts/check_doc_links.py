#!/usr/bin/env python3
"""Checks the relative links of the Markdown files: every linked file exists, and every
`#anchor` names a heading of its file (GitHub's rule: lower case, punctuation dropped but `-`
and `_`, spaces to `-`, a repeated heading numbered `-1`, `-2`, …).

    python3 scripts/check_doc_links.py            # README.md, docs/**/*.md; exit 1 on a broken link

Run by .ci/run, so that moving a document or renaming a section cannot leave a dead link
(docs/PERFORMANCE.md became a summary and its log moved to docs/dev/ in issue [3.2]).
External links (http, https, mailto) are not checked: CI has no business with the network.
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading."""
    text = re.sub(r"<[^>]+>", "", heading).strip().lower()
    text = "".join(ch for ch in text if ch.isalnum() or ch in " -_")
    return text.replace(" ", "-")


def prose_lines(path: Path):
    """The lines of a Markdown file outside code fences."""
    fenced = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield line


def anchors(path: Path) -> set:
    seen: dict = {}
    out = set()
    for line in prose_lines(path):
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        base = slug(m.group(1))
        n = seen.get(base, 0)
        seen[base] = n + 1
        out.add(base if n == 0 else f"{base}-{n}")
    return out


def broken_links(path: Path):
    for number, line in enumerate(prose_lines(path), 1):
        # inline code is not a link
        line = re.sub(r"`[^`]*`", "", line)
        for m in LINK.finditer(line):
            target = m.group(1) or m.group(2)
            if re.match(r"^[a-z]+:", target):
                continue
            file_part, _, anchor = target.partition("#")
            linked = (path.parent / file_part).resolve() if file_part else path
            if not linked.exists():
                yield f"{path.relative_to(ROOT)}: {target}: no such file"
            elif anchor and linked.suffix == ".md" and anchor not in anchors(linked):
                yield f"{path.relative_to(ROOT)}: {target}: no heading with this anchor in {linked.relative_to(ROOT)}"


def main() -> int:
    files = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    problems = [p for f in files for p in broken_links(f)]
    for p in problems:
        print(p, file=sys.stderr)
    print(f"{len(files)} Markdown files, {'no broken link' if not problems else f'{len(problems)} broken links'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
