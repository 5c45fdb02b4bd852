#!/usr/bin/env python3
"""Every relative link in README.md and docs/*.md resolves: the file exists and, for a #anchor
into a markdown file, a heading of that file has that anchor (GitHub's rule: lower case, spaces
to '-', punctuation other than '-' and '_' dropped). Usage: check_links.py REPO_ROOT"""
import re
import sys
from pathlib import Path

LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^ {0,3}(```|~~~)")
CLOSE = re.compile(r"^ {0,3}(```|~~~)\s*$")  # a closing fence has no info string


def anchor(heading):
    text = re.sub(r"`([^`]*)`", r"\1", heading.strip().lower())
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        found, seen, fenced = set(), {}, False
        for line in path.read_text(encoding="utf-8").splitlines():
            if (CLOSE if fenced else FENCE).match(line):
                fenced = not fenced
            elif not fenced and line.startswith("#"):
                a = anchor(line.lstrip("#"))
                n = seen.get(a, 0)
                seen[a] = n + 1
                found.add(a if n == 0 else f"{a}-{n}")
        cache[path] = found
    return cache[path]


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    pages = [root / "README.md"] + sorted((root / "docs").glob("*.md"))
    bad = []
    for page in pages:
        fenced = False
        for no, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1):
            if (CLOSE if fenced else FENCE).match(line):
                fenced = not fenced
                continue
            if fenced:
                continue
            for m in LINK.finditer(line):
                target = m.group(1) or m.group(2)
                if re.match(r"^[a-z]+:", target):  # http:, https:, mailto:
                    continue
                path, _, frag = target.partition("#")
                dest = (page.parent / path).resolve() if path else page
                where = f"{page.relative_to(root)}:{no}: {target}"
                if not dest.exists():
                    bad.append(f"{where}: no such file")
                elif frag and dest.suffix == ".md" and frag not in anchors(dest):
                    bad.append(f"{where}: no heading with this anchor")
    for b in bad:
        print(b)
    print(f"{len(pages)} pages checked, {len(bad)} broken links")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
