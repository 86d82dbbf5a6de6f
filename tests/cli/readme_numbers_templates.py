#!/usr/bin/env python3
"""readme_numbers_templates.py ROOT: the templates of tools/readme_numbers.py's generated blocks.

A template fills its placeholders and keeps or drops its sections; a block's page keeps its
template when the block is rewritten; and each fault a typo makes is refused, naming it: a
placeholder the function gives no value for, a value the template does not use, a value of the
wrong type, a brace outside a placeholder, a section not closed, a template for a function that
returns the whole text and the converse."""
import importlib.util
import os
import sys

spec = importlib.util.spec_from_file_location("readme_numbers", os.path.join(sys.argv[1], "tools", "readme_numbers.py"))
rn = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rn)
problems = []


def expect(what, got, want):
    if got != want:
        problems.append(f"{what}: got {got!r}, want {want!r}")


def refused(what, call, says):
    try:
        call()
    except (ValueError, SystemExit) as e:
        if says not in str(e):
            problems.append(f"{what}: refused with {str(e)!r}, which does not say {says!r}")
        return
    problems.append(f"{what}: not refused")


template = "{n} run{#plural}s{/plural}{^plural} alone{/plural}: {#failed}{which} {#one}fails{/one}{^one}fail{/one}{/failed}."
values = {"n": "3", "plural": True, "failed": True, "which": "fixed+60", "one": True}
expect("placeholders and nested sections", rn.fill(template, values), "3 runs: fixed+60 fails.")
expect("sections dropped", rn.fill(template, {**values, "plural": False, "failed": False}), "3 run alone: .")

refused("a placeholder without a value", lambda: rn.fill("{n} runs, {m} gyros", {"n": "3"}), "names m")
refused("a value no placeholder uses", lambda: rn.fill("{n} runs", {"n": "3", "m": "4"}), "gives m")
refused("a misspelt placeholder", lambda: rn.fill("{runs_} runs", {"runs": "3"}), "names runs_")
refused("a number where a string belongs", lambda: rn.fill("{n} runs", {"n": 3}), "must be a str")
refused("a string where a section's boolean belongs", lambda: rn.fill("{#ok}yes{/ok}", {"ok": "yes"}),
        "must be a bool")
refused("a name used as a value and as a section", lambda: rn.fill("{ok}{#ok}!{/ok}", {"ok": True}),
        "both a value and a section")
refused("a brace outside a placeholder", lambda: rn.fill("{n} runs {", {"n": "3"}), "not a placeholder")
refused("a placeholder in capitals", lambda: rn.fill("{N} runs", {"N": "3"}), "not a placeholder")
refused("a section not closed", lambda: rn.fill("{#ok}yes", {"ok": True}), "not closed")
refused("a section closed by another name", lambda: rn.fill("{#ok}yes{/no}", {"ok": True}), "closes no open section")
refused("a template for a function that returns the text", lambda: rn.render_block("{n}", "3 runs"),
        "has a template")
refused("values for a block without a template", lambda: rn.render_block(None, {"n": "3"}), "no template")

# A page: the block's template stays, its text is what the template makes of the values.
page = ("Before.\n<!-- generated: demo\nHeld out: {n} runs{#ok}, all pass{/ok}.\n-->\nstale\n<!-- end: demo -->\n"
        "<!-- generated: table -->\n| a |\n<!-- end: table -->\nAfter.\n")
rn.BLOCKS = {"demo": lambda r: {"n": "4", "ok": True}, "table": lambda r: "| b |"}
expect("a page rewritten", rn.render("page.md", page, None),
       "Before.\n<!-- generated: demo\nHeld out: {n} runs{#ok}, all pass{/ok}.\n-->\nHeld out: 4 runs, all pass.\n"
       "<!-- end: demo -->\n<!-- generated: table -->\n| b |\n<!-- end: table -->\nAfter.\n")
rn.BLOCKS["demo"] = lambda r: {"n": "4", "ok": True, "gyros": "200"}
refused("a page whose template misses a value", lambda: rn.render("page.md", page, None),
        "page.md, block 'demo': the script gives gyros")

for p in problems:
    print(p)
print(f"{len(problems)} problem(s)" if problems else "every template fault is refused")
sys.exit(1 if problems else 0)
