#!/usr/bin/env python3
"""Checks that the harness's layers include only downwards.

The harness (scenarios/harness/) is built in layers, each a CMake target that links only the ones
below it: loop < evaluation < reports < runners < cli. A file may include headers of its own layer
and of the layers below; an include of a layer above (`#include "runners/batch.h"` in
evaluation/) is an error. Exit code 1 lists every such include with its file and line; ctest runs
this over scenarios/harness (HarnessLayers.IncludesOnlyDownwards).
"""
import argparse
import pathlib
import re
import sys

LAYERS = ["loop", "evaluation", "reports", "runners", "cli"]
INCLUDE = re.compile(r'^\s*#\s*include\s*"([a-z_]+)/[^"]+"', re.MULTILINE)


def violations(root):
    """Yields (path, line number, included layer, own layer) of each include going up a layer."""
    for own_rank, own in enumerate(LAYERS):
        for path in sorted((root / own).rglob("*")):
            if path.suffix not in (".h", ".cc"):
                continue
            text = path.read_text(encoding="utf-8", errors="replace")
            for match in INCLUDE.finditer(text):
                layer = match.group(1)
                if layer in LAYERS and LAYERS.index(layer) > own_rank:
                    yield path, text.count("\n", 0, match.start()) + 1, layer, own


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", type=pathlib.Path, help="the harness folder (holding loop/, evaluation/, ...)")
    args = parser.parse_args()
    missing = [layer for layer in LAYERS if not (args.root / layer).is_dir()]
    if missing:
        print(f"{args.root}: no layer folder {', '.join(missing)} (expected {', '.join(LAYERS)})")
        return 2
    found = list(violations(args.root))
    for path, line, layer, own in found:
        print(f"{path}:{line}: includes {layer}/, a layer above {own}/ ({' < '.join(LAYERS)})")
    print(f"{len(found)} include(s) up a layer")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
