#!/usr/bin/env python3
"""Print what installing a local project needs from an index, one requirement per line.

    tools/pyproject-requirements.py DIR[EXTRA,...]   e.g. tools/pyproject-requirements.py '.[test]'

That is: DIR/pyproject.toml's [build-system] requires (pip's build isolation installs them
to build even an editable install), its [project] dependencies, and the optional
dependencies of the extras named.  tools/pip-install-cached.sh fills its wheelhouse with
them.  Needs Python >= 3.11 (tomllib).  Exits non-zero, with a message, if the
dependencies are dynamic (they cannot be read without running the build backend).
"""

import re
import sys
import tomllib
from pathlib import Path


def main(arg: str) -> list[str]:
    m = re.fullmatch(r"(.*?)(?:\[([^\]]*)\])?", arg.strip())
    where, extras = m[1] or ".", [e.strip() for e in (m[2] or "").split(",") if e.strip()]
    with open(Path(where) / "pyproject.toml", "rb") as f:
        data = tomllib.load(f)

    # PEP 518: without a [build-system] table, pip builds with setuptools (and wheel).
    reqs = list(data.get("build-system", {}).get("requires", ["setuptools>=40.8.0", "wheel"]))
    project = data.get("project", {})
    dynamic = set(project.get("dynamic", []))
    if dynamic & {"dependencies", "optional-dependencies"}:
        sys.exit(f"{where}/pyproject.toml: dependencies are dynamic, cannot list them")
    reqs += project.get("dependencies", [])
    optional = project.get("optional-dependencies", {})
    for extra in extras:
        reqs += optional.get(extra, [])  # pip, too, only warns about an unknown extra
    return reqs


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(f"usage: {sys.argv[0]} DIR[EXTRA,...]")
    print("\n".join(main(sys.argv[1])))
