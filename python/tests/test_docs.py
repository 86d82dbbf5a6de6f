"""Every Python example of the README's Python section and of docs/python.md runs: each
page's ```python blocks in order, in one namespace, from the repository directory, as a reader
would paste them. A block fenced ```py instead is shown, not run: it needs what a test machine
does not have (a Dask cluster, docs/python.md "Populations")."""
import contextlib
import io
import os
import re

import pytest

from conftest import SOURCE


def python_blocks(text):
    return re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)


def readme_python_section():
    text = (SOURCE / "README.md").read_text()
    start = text.index("\n## Python\n")
    return text[start:text.index("\n## ", start + 1)]


PAGES = {"README.md#python": readme_python_section, "docs/python.md": lambda: (SOURCE / "docs/python.md").read_text()}


@pytest.mark.parametrize("page", PAGES)
def test_the_python_examples_run(page, monkeypatch):
    blocks = python_blocks(PAGES[page]())
    assert blocks, f"{page}: no ```python block found"
    monkeypatch.chdir(SOURCE)
    namespace = {}
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        for i, block in enumerate(blocks):
            exec(compile(block, f"{page} block {i + 1}", "exec"), namespace)
    assert out.getvalue().strip(), f"{page}: the examples printed nothing"
    assert "nan" not in out.getvalue()


def test_the_readme_links_the_guide_and_the_example():
    section = readme_python_section()
    assert "docs/python.md" in section and "python/examples/first_steps.py" in section
    assert os.path.exists(SOURCE / "python/examples/first_steps.py")


@pytest.mark.parametrize("page", PAGES)
def test_the_python_shown_but_not_run_compiles(page):
    for i, block in enumerate(re.findall(r"^```py\n(.*?)^```$", PAGES[page](), flags=re.S | re.M)):
        compile(block, f"{page} ```py block {i + 1}", "exec")  # a SyntaxError fails the test


def test_the_readme_quotes_what_its_python_tour_prints(monkeypatch):
    """The README shows the tour's output in the plain ``` block after "It prints": it must be
    what the tour prints, to the character."""
    section = readme_python_section()
    quoted = re.search(r"It prints[^\n]*\n\n```\n(.*?)^```$", section, flags=re.S | re.M)
    assert quoted, "README.md#python: no ``` block after 'It prints'"
    monkeypatch.chdir(SOURCE)
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.warns(UserWarning, match="outside the fitted range"):
        namespace = {}
        for i, block in enumerate(python_blocks(section)):
            exec(compile(block, f"README.md#python block {i + 1}", "exec"), namespace)
    assert out.getvalue() == quoted.group(1)
