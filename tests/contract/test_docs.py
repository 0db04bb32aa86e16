"""The documentation's sources: every public module is on the API page, and the demo
converter reads jupytext scripts as the demos are written (``docs/_ext/rwall_docs.py``).

The site itself is built by ``make docs`` (warnings as errors), which ``make test`` runs.
"""

import importlib
import importlib.util
import pkgutil
import re
from pathlib import Path

import pytest

import rwall_fem

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def rwall_docs():
    spec = importlib.util.spec_from_file_location("rwall_docs", ROOT / "docs/_ext/rwall_docs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_public_module_is_on_the_api_page():
    """A module is there with its own automodule, or through its package's when the
    package's ``__all__`` re-exports its names (``rwall_fem.scene``); a package is there
    through its modules."""
    page = (ROOT / "docs/api.md").read_text()
    modules = [
        info.name
        for info in pkgutil.walk_packages(rwall_fem.__path__, "rwall_fem.")
        if not any(part.startswith("_") for part in info.name.split("."))
    ]

    def on_page(name):
        return f".. automodule:: {name}\n" in page

    def through_package(name):
        package = name.rpartition(".")[0]
        names = set(getattr(importlib.import_module(name), "__all__", ()))
        return on_page(package) and bool(names & set(importlib.import_module(package).__all__))

    missing = [
        name
        for name in modules
        if not on_page(name)
        and not through_package(name)
        and not any(on_page(other) for other in modules if other.startswith(name + "."))
    ]
    assert not missing, f"add to docs/api.md: {missing}"


def test_light_format_cells(rwall_docs):
    script = "\n".join(
        [
            "# # Title",
            "#",
            "# Prose.",
            "",
            "# +",
            "import numpy  # a comment",
            "",
            "# a comment inside the cell",
            "x = 1",
            "# -",
            "",
            "# ## A heading right above its code",
            "y = x + 1",
            "    # an indented comment is code",
            "",
            "# %% [markdown]",
            "# Percent-format prose.",
            "# %%",
            "z = y",
        ]
    )
    cells = rwall_docs._cells(script)
    kinds = [kind for kind, _ in cells]
    assert kinds == ["markdown", "code", "markdown", "code", "markdown", "code"]
    assert cells[0][1] == ["# Title", "", "Prose."]
    assert "# a comment inside the cell" in cells[1][1]
    assert cells[2][1] == ["## A heading right above its code"]
    assert cells[3][1] == ["y = x + 1", "    # an indented comment is code"]
    assert cells[4][1] == ["Percent-format prose."]


def test_every_demo_becomes_a_page(rwall_docs):
    for path in sorted((ROOT / "demos").glob("demo_*.py")):
        page, summary = rwall_docs.python_demo_markdown(path)
        assert page.startswith("# ") and summary and "```python" in page, path.name
    for path in sorted((ROOT / "demos").glob("*.toml")):
        page, summary = rwall_docs.scene_markdown(path)
        assert page.startswith("# ") and summary and "{literalinclude}" in page, path.name


def test_pointers_into_the_theory_name_its_sections():
    """Code and tests point at ``docs/theory.md, "Section"``: each names a heading there
    (or the start of one: "Chatter")."""
    headings = [
        line.lstrip("#").strip().lower()
        for line in (ROOT / "docs/theory.md").read_text().splitlines()
        if line.startswith("#")
    ]
    pointer = re.compile(r'theory\.md`{0,2},?\s*\(?(?:section\s+)?"([^"]+)"')
    sources = [*(ROOT / "rwall_fem").rglob("*.py"), *(ROOT / "rwall_fem").rglob("*.[ch]")]
    sources += [p for p in (ROOT / "tests").rglob("*.py") if p != Path(__file__).resolve()]
    wrong = []
    for path in sources:
        for match in pointer.finditer(path.read_text()):
            name = " ".join(re.sub(r"\n\s*[#*]?", " ", match.group(1)).split()).lower()
            if not any(h.startswith(name) for h in headings):
                wrong.append(f"{path.relative_to(ROOT)}: {match.group(1)!r}")
    assert not wrong, f"no such section in docs/theory.md: {wrong}"
