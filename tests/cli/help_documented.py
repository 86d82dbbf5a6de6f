#!/usr/bin/env python3
"""help_documented.py RLGTHERM CLI_MD: docs/cli.md documents every verb and option `rlgtherm
--help` and `rlgtherm VERB --help` list, and nothing they do not.

- each verb has a section `## VERB` whose synopsis (its first ``` block) starts `rlgtherm VERB`
  and names each of the verb's options (one of its spellings, `-o` or `--output`), and names no
  option the verb does not have;
- the options of `rlgtherm --help` itself (`--help`, `--version`) appear in the page;
- the page's "N verbs" is the number of verbs.
`-h,--help` of a verb is the convention the page states once, not repeated in each synopsis."""
import re
import subprocess
import sys

rlg, page = sys.argv[1], sys.argv[2]
problems = []

NUMBERS = {w: i for i, w in enumerate("zero one two three four five six seven eight nine ten eleven twelve thirteen "
                                      "fourteen fifteen sixteen seventeen eighteen nineteen twenty".split())}
OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z][\w-]*)")


def help_sections(args):
    """The lines of each section ("Options", "Subcommands", ...) of CLI11's help text."""
    out = subprocess.run([rlg] + args + ["--help"], capture_output=True, text=True, check=True).stdout
    sections, current = {}, None
    for line in out.splitlines():
        m = re.match(r"^(\w[\w ]*):$", line)
        if m:
            current = m.group(1)
            sections[current] = []
        elif current and line.startswith("  ") and line.strip():
            sections[current].append(line.strip())
    return sections


def options(lines):
    """Each option's spellings, from lines like "-o,--output TEXT  what it does"."""
    return [tuple(line.split()[0].split(",")) for line in lines if line.startswith("-")]


text = open(page, encoding="utf-8").read()
sections = {}
for block in re.split(r"^## ", text, flags=re.M)[1:]:
    title, _, body = block.partition("\n")
    sections[title.strip()] = body

top = help_sections([])
verbs = [line.split()[0] for line in top.get("Subcommands", [])]
if not verbs:
    problems.append("`rlgtherm --help` lists no verbs")
for spellings in options(top.get("Options", [])):
    if not any(re.search(r"(?<![\w-])" + re.escape(s) + r"(?![\w-])", text) for s in spellings):
        problems.append(f"`rlgtherm {'/'.join(spellings)}` is not in {page}")
m = re.search(r"\b(\w+) verbs\b", text)
if not m or NUMBERS.get(m.group(1)) != len(verbs):
    problems.append(f"{page} says '{m.group(0) if m else 'no number of verbs'}'; rlgtherm has {len(verbs)}: "
                    f"{', '.join(verbs)}")

for verb in verbs:
    body = sections.get(verb)
    if body is None:
        problems.append(f"no section '## {verb}' in {page}")
        continue
    synopsis = re.search(r"```\n(.*?)```", body, flags=re.S)
    if not synopsis or not re.search(rf"\brlgtherm {verb}\b", synopsis.group(1)):
        problems.append(f"'## {verb}': no synopsis starting 'rlgtherm {verb}' in its first ``` block")
        continue
    written = set(OPTION.findall(synopsis.group(1)))
    known = set()
    for spellings in options(help_sections([verb]).get("Options", [])):
        known.update(spellings)
        if "--help" in spellings:
            continue
        if not written.intersection(spellings):
            problems.append(f"'## {verb}': option {'/'.join(spellings)} of `rlgtherm {verb} --help` is not in its synopsis")
    for option in sorted(written - known):
        problems.append(f"'## {verb}': the synopsis names {option}, which `rlgtherm {verb} --help` does not list")

for p in problems:
    print("FAIL:", p)
print(f"{len(verbs)} verbs checked against {page}: {len(problems)} problem(s)")
sys.exit(1 if problems else 0)
