"""Strip outputs from notebooks before committing, keeping cells marked NBVAL_CHECK_OUTPUT.

    python tools/strip_notebooks.py notebooks/*.ipynb          # rewrite in place (atomically)
    python tools/strip_notebooks.py --check notebooks/*.ipynb  # exit 1 if any would change
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile

CHECK_MARK = "NBVAL_CHECK_OUTPUT"


def is_checked(cell: dict) -> bool:
    source = "".join(cell.get("source", []))
    return CHECK_MARK in source.splitlines()[0] if source else False


def strip(nb: dict) -> dict:
    """Remove outputs and execution counts from every code cell that is not a checked cell."""
    for cell in nb.get("cells", []):
        if cell.get("cell_type") != "code":
            continue
        if not is_checked(cell):
            cell["outputs"] = []
            cell["execution_count"] = None
        else:  # keep the checked text output only, never images
            cell["outputs"] = [o for o in cell.get("outputs", []) if o.get("output_type") == "stream"
                               or "text/plain" in o.get("data", {})]
            # nbval treats a cell without an execution count as unrun and refuses its outputs
            cell["execution_count"] = cell.get("execution_count") or 1
            for o in cell["outputs"]:
                if "data" in o:
                    o["data"] = {"text/plain": o["data"]["text/plain"]}
        cell.get("metadata", {}).pop("execution", None)
    nb.get("metadata", {}).pop("widgets", None)
    return nb


def dumps(nb: dict) -> str:
    return json.dumps(nb, indent=1, ensure_ascii=False) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--check", action="store_true", help="only report notebooks that are not stripped")
    args = parser.parse_args(argv)
    dirty = []
    for path in args.paths:
        with open(path) as f:
            text = f.read()
        new = dumps(strip(json.loads(text)))
        if new == text:
            continue
        dirty.append(path)
        if not args.check:
            fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path) or ".", suffix=".ipynb.tmp")
            with os.fdopen(fd, "w") as f:
                f.write(new)
            os.replace(tmp, path)
    for path in dirty:
        print(("not stripped: " if args.check else "stripped: ") + path)
    return 1 if (args.check and dirty) else 0


if __name__ == "__main__":
    sys.exit(main())
