"""Pages made from the repository's own files when the documentation builds.

- **Tutorials** (``docs/tutorials/``, written at every build, not committed): one page per
  demo. A Python demo (``demos/demo_*.py``) is a jupytext script in the light format
  (``# +`` / ``# -`` around code cells) or the percent format (``# %%``): the comment lines
  at column 0 that open a block are markdown, the rest is code, as the DOLFINx demos read.
  A scene (``demos/*.toml``) becomes its opening comment as prose, its picture and the
  whole file. Pictures are the committed ones, ``docs/gallery/NAME.png`` (for a Python
  demo without its own, the picture of the scene of the same name without ``demo_``);
  nothing is run.
- **Docstrings**: they are plain text with reST literals and roles, where ``|x|`` is an
  absolute value; autodoc reads them with every ``|`` outside literals escaped, so that
  reST does not take ``|dx|`` for a substitution.
- **Test cases**: a line ``<!-- rwall-docs: test-cases FOLDER -->`` in a page is replaced by
  one section per ``FOLDER/test_*.py``: its module docstring (the reference it compares
  with) and its test functions (their names and the first line of their docstrings).

A new demo, a new picture or a new test file therefore needs no edit here or in the pages.

Why a converter and not myst-nb: the demos are never executed by the docs build, the
scenes need converting anyway, and this keeps the build to Sphinx and MyST (no Jupyter
stack to install); the reading rule also keeps a heading comment directly above its code
(``# ## Run`` then ``sim.run()``) as a heading, where jupytext would fold it into the code.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

__all__ = ["escape_bars", "python_demo_markdown", "scene_markdown", "setup", "test_cases_markdown"]

ROOT = Path(__file__).resolve().parents[2]
DEMOS = ROOT / "demos"
GALLERY = ROOT / "docs" / "gallery"
TUTORIALS = ROOT / "docs" / "tutorials"
MARKER = re.compile(r"^<!-- rwall-docs: test-cases (\S+) -->$", re.MULTILINE)
# :mod:`x` (reST, in docstrings) -> {mod}`x` (MyST)
ROLE = re.compile(r":(\w+):`")


# ---- demos --------------------------------------------------------------------------------
def _title(stem: str) -> str:
    return stem.removeprefix("demo_").replace("_", " ").capitalize()


def _picture(stem: str) -> tuple[Path, str] | None:
    """The gallery picture of demo ``stem`` and a caption, or None."""
    own = GALLERY / f"{stem}.png"
    if own.exists():
        return own, ""
    scene = stem.removeprefix("demo_")
    other = GALLERY / f"{scene}.png"
    if stem.startswith("demo_") and other.exists() and (DEMOS / f"{scene}.toml").exists():
        return other, f"The scene [`{scene}.toml`]({scene}.md): the same problem on its own mesh."
    return None


def _figure(stem: str) -> list[str]:
    found = _picture(stem)
    if found is None:
        return []
    path, caption = found
    return ["", f"```{{figure}} ../gallery/{path.name}", f":alt: {stem}", "", caption, "```", ""]


def _is_prose(line: str) -> bool:
    """A markdown line of a light-format script: a comment at column 0 (not a cell marker)."""
    if line.strip() in ("# +", "# -") or line.startswith(("#!", "# %%", "# noqa")):
        return False
    return line == "#" or line.startswith("# ")


def _cells(text: str) -> list[tuple[str, list[str]]]:
    """``[("markdown" | "code", lines), ...]`` of a light- or percent-format script."""
    cells: list[tuple[str, list[str]]] = []

    def add(kind, lines):
        while lines and not lines[-1].strip():
            lines = lines[:-1]
        while lines and not lines[0].strip():
            lines = lines[1:]
        if not lines:
            return
        if cells and cells[-1][0] == kind:
            cells[-1][1].extend(["", *lines])
        else:
            cells.append((kind, list(lines)))

    lines = text.splitlines()
    i = 0
    block: list[str] = []

    def flush(block):
        """A block between blank lines: its opening prose lines, then code."""
        j = 0
        while j < len(block) and _is_prose(block[j]):
            j += 1
        add("markdown", [line[2:] if line.startswith("# ") else "" for line in block[:j]])
        add("code", block[j:])

    while i < len(lines):
        line = lines[i]
        if line.strip() == "# +":  # an explicit code cell, up to "# -"
            flush(block)
            block = []
            j = i + 1
            while j < len(lines) and lines[j].strip() != "# -":
                j += 1
            add("code", lines[i + 1 : j])
            i = j + 1
        elif line.startswith("# %%"):  # percent format: a cell up to the next marker
            flush(block)
            block = []
            j = i + 1
            while j < len(lines) and not lines[j].startswith("# %%"):
                j += 1
            body = lines[i + 1 : j]
            if "[markdown]" in line:
                add("markdown", [b[2:] if b.startswith("# ") else "" for b in body])
            else:
                add("code", body)
            i = j
        elif not line.strip():
            flush(block)
            block = []
            i += 1
        else:
            block.append(line)
            i += 1
    flush(block)
    return cells


def python_demo_markdown(path: Path) -> tuple[str, str]:
    """The page of a Python demo, and its one-line summary for the index."""
    cells = _cells(path.read_text())
    out: list[str] = []
    summary = ""
    figure_done = False
    for kind, lines in cells:
        if kind == "code":
            if not figure_done:
                out += _figure(path.stem)
                figure_done = True
            out += ["", "```python", *lines, "```", ""]
            continue
        if not out and lines[0].startswith("# "):
            title = lines[0]
            lines = lines[1:]
            out.append(title)
            summary = title[2:]
        if not summary:
            summary = lines[0]
        out += ["", *lines, ""]
    if not out or not out[0].startswith("# "):
        out.insert(0, f"# {_title(path.stem)}")
    if not figure_done:
        out += _figure(path.stem)
    out += [
        "",
        f"The whole script: {{download}}`{path.name} <../../demos/{path.name}>`; it writes "
        f"into `results/{path.stem}/`.",
        "",
    ]
    return "\n".join(out), summary


def scene_markdown(path: Path) -> tuple[str, str]:
    """The page of a scene demo, and its one-line summary for the index. An optional first
    line ``# # Title`` gives the title; otherwise it is made from the file name."""
    lines = path.read_text().splitlines()
    prose = []
    for line in lines:
        if not (line == "#" or line.startswith("# ")):
            break
        prose.append(line[2:])
    title = _title(path.stem)
    if prose and prose[0].startswith("# "):
        title = prose.pop(0)[2:]
    text = " ".join(p.strip() for p in prose)
    summary = text.split(". ")[0].rstrip(".") + "." if text else ""
    out = [f"# {title}", "", *prose, ""]
    out += _figure(path.stem)
    out += [
        "Run it (results in `results/" + path.stem + "/`):",
        "",
        "```sh",
        f".venv/bin/rwall-fem check demos/{path.name}   # what would run: cells, step, walls",
        f".venv/bin/rwall-fem run demos/{path.name} --out results/{path.stem}",
        "```",
        "",
        "## The scene",
        "",
        f"```{{literalinclude}} ../../demos/{path.name}",
        ":language: toml",
        "```",
        "",
        f"Download: {{download}}`{path.name} <../../demos/{path.name}>`. Every key is "
        "explained in the [scene reference](../reference/scene.md).",
        "",
    ]
    return "\n".join(out), summary


def _demo_order(path: Path) -> tuple:
    """``make demo``'s scene first, the scene with every key last."""
    return (path.stem != "bar_impact", path.stem == "every_key", path.stem)


def _tidy(text: str) -> str:
    """One blank line at most between markdown blocks (code blocks are left as they are)."""
    out, fenced = [], False
    for line in text.splitlines():
        if line.startswith("```"):
            fenced = not fenced if line == "```" or not fenced else fenced
        if not fenced and not line.strip() and out and not out[-1].strip():
            continue
        out.append(line)
    return "\n".join(out).strip() + "\n"


def _write(path: Path, text: str) -> None:
    """Write only a changed page, so that Sphinx rereads only what changed."""
    text = _tidy(text)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def write_tutorials() -> list[Path]:
    """Write ``docs/tutorials/`` (index and one page per demo); returns the demo files."""
    TUTORIALS.mkdir(exist_ok=True)
    python = sorted(DEMOS.glob("demo_*.py"))
    scenes = sorted(DEMOS.glob("*.toml"), key=_demo_order)
    wanted = {"index.md"}
    index = [
        "# Tutorials",
        "",
        "The demos of `demos/`, as pages. `make demo` runs the first scene, `make demos` "
        "runs them all into `results/`. The Python demos are scripts in the style of the "
        "DOLFINx demos (jupytext, light format): read top to bottom, or run them with "
        "`python demos/NAME.py` (or under `mpirun -n 2`).",
        "",
    ]
    for heading, files, make in (
        ("Scenes", scenes, scene_markdown),
        ("From Python", python, python_demo_markdown),
    ):
        index += [f"## {heading}", "", "| | demo | what |", "|---|---|---|"]
        for path in files:
            page, summary = make(path)
            _write(TUTORIALS / f"{path.stem}.md", page)
            wanted.add(f"{path.stem}.md")
            found = _picture(path.stem)
            thumb = f"![{path.stem}](../gallery/{found[0].name}){{w=160px}}" if found else ""
            index.append(f"| {thumb} | [`{path.name}`]({path.stem}.md) | {summary} |")
        index.append("")
    index += ["```{toctree}", ":hidden:", ""]
    index += [p.stem for p in scenes] + [p.stem for p in python]
    index += ["```", ""]
    _write(TUTORIALS / "index.md", "\n".join(index))
    for stale in TUTORIALS.glob("*.md"):
        if stale.name not in wanted:
            stale.unlink()
    return python + scenes


# ---- test cases ---------------------------------------------------------------------------
def _myst(docstring: str) -> str:
    """A reST-flavoured docstring as MyST markdown (roles; ``x`` is a code span in both)."""
    return ROLE.sub(r"{\1}`", docstring)


def test_cases_markdown(folder: str) -> tuple[str, list[Path]]:
    """One section per ``folder/test_*.py`` (relative to the repository)."""
    out, files = [], sorted((ROOT / folder).glob("test_*.py"))
    for path in files:
        module = ast.parse(path.read_text())
        doc = ast.get_docstring(module) or "(no module docstring)"
        first, _, rest = doc.partition("\n\n")
        rel = path.relative_to(ROOT).as_posix()
        out += [f"### `{rel}`", "", _myst(" ".join(first.split())), ""]
        if rest.strip():
            out += [_myst(rest.strip()), ""]
        tests = [
            node
            for node in module.body
            if isinstance(node, ast.FunctionDef) and node.name.startswith("test_")
        ]
        if tests:
            out += ["Tests:", ""]
        for node in tests:
            line = (ast.get_docstring(node) or "").strip().split("\n\n")[0]
            name = node.name.removeprefix("test_").replace("_", " ")
            out.append(f"- *{name}*" + (f": {_myst(' '.join(line.split()))}" if line else ""))
        out.append("")
    return "\n".join(out), files


# ---- docstrings --------------------------------------------------------------------------
LITERAL = re.compile(r"(``.*?``)")


def escape_bars(line: str) -> str:
    """``line`` with each ``|`` outside ````literals```` escaped for reST."""
    parts = LITERAL.split(line)
    return "".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def _process_docstring(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = [escape_bars(line) for line in lines]


# ---- Sphinx hooks -------------------------------------------------------------------------
def _builder_inited(app) -> None:
    write_tutorials()


def _source_read(app, docname: str, source: list[str]) -> None:
    def expand(match):
        text, files = test_cases_markdown(match.group(1))
        for path in files:
            app.env.note_dependency(str(path))
        return text

    source[0] = MARKER.sub(expand, source[0])


def setup(app):
    app.connect("builder-inited", _builder_inited)
    app.connect("source-read", _source_read)
    app.connect("autodoc-process-docstring", _process_docstring)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
