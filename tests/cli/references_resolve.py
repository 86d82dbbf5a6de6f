#!/usr/bin/env python3
"""Every reference a tracked file makes to a section of the project's markdown, written
FILE, "Section" (docs/performance.md, "Simulation"; docs/plan.md, "Service"), or as a link FILE.md#anchor in
markdown, resolves: the file exists (a bare name is looked for beside the citing file, then in
each folder above it up to the repository's root) and holds a heading that starts with the
section's words, or whose GitHub anchor is the link's. Prints each that does not; exit 1 if any.

usage: references_resolve.py REPO_ROOT"""
import pathlib
import re
import subprocess
import sys

root = pathlib.Path(sys.argv[1]).resolve()
files = subprocess.run(["git", "-C", str(root), "ls-files", "-z"], capture_output=True, check=True).stdout.decode().split("\0")
TEXT = (".h", ".cpp", ".py", ".pyi", ".sh", ".toml", ".txt", ".md", ".cmake", ".json")
CITE = re.compile(r'\b((?:[\w./-]+/)?(?:README(?:\.md)?|[\w-]+\.md)),\s+"([^"]+)"')
LINK = re.compile(r'\]\(((?:[\w./-]+/)?[\w-]+\.md)#([\w-]+)\)')


def headings(path):
    out = []
    in_code = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            in_code = not in_code
        elif not in_code and line.startswith("#"):
            out.append(line.lstrip("#").strip())
    return out


def anchor(heading):
    """GitHub's anchor of a heading: lower case, punctuation but hyphens and underscores out, spaces to hyphens."""
    h = re.sub(r"[^\w\- ]", "", heading.lower())
    return h.replace(" ", "-")


def find(citing, name):
    if name in ("README",):
        name = "README.md"
    if "/" in name:
        candidates = [root / name, citing.parent / name]
    else:
        candidates = [d / name for d in [citing.parent, *citing.parent.parents] if d == root or root in d.parents]
    return next((c for c in candidates if c.is_file()), None)


bad = []
for rel in files:
    # Data and fuzzing inputs are read, not cited from.
    if not rel.endswith(TEXT) or rel.startswith(("data/", "tests/reference/data", "tests/fuzz/corpus/")):
        continue
    path = root / rel
    try:
        text = path.read_text(encoding="utf-8")
    except (UnicodeDecodeError, FileNotFoundError):
        continue
    for n, line in enumerate(text.splitlines(), 1):
        for m in CITE.finditer(line):
            target = find(path, m.group(1))
            section = m.group(2)
            if target is None:
                bad.append(f"{rel}:{n}: {m.group(1)}, \"{section}\": no such file")
            elif not any(h.lower().startswith(section.lower()) for h in headings(target)):
                bad.append(f"{rel}:{n}: {m.group(1)}, \"{section}\": {target.relative_to(root)} has no heading that starts so")
        if rel.endswith(".md"):
            for m in LINK.finditer(line):
                target = (path.parent / m.group(1)).resolve()
                if not target.is_file():
                    bad.append(f"{rel}:{n}: {m.group(1)}#{m.group(2)}: no such file")
                elif m.group(2) not in {anchor(h) for h in headings(target)}:
                    bad.append(f"{rel}:{n}: {m.group(1)}#{m.group(2)}: {target.relative_to(root)} has no such heading")
for b in bad:
    print(b)
print(f"{len(bad)} references that do not resolve")
sys.exit(1 if bad else 0)
