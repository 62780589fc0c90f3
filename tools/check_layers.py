#!/usr/bin/env python3
"""Fails when a source file includes a header from a layer above its own.

The layers (docs/architecture.md), each allowed to include only itself and the layers listed:
a project header is named by its top folder ("base/status.h"), so the folder of the includer and
the folder of the included file say whether the arrow points down.
Usage: check_layers.py [SOURCE_DIR]
"""
import pathlib
import re
import sys

ALLOWED = {
    "base": {"base"},
    "protocol": {"base", "protocol"},
    "solver": {"base", "solver"},
    "config": {"base", "config"},
    "netlists": {"base", "protocol", "solver", "config", "netlists"},
    "eye": {"base", "protocol", "config", "eye"},
    "analysis": {"base", "protocol", "solver", "config", "netlists", "eye", "analysis"},
    "reports": {"base", "protocol", "solver", "config", "netlists", "eye", "analysis", "reports"},
    "cli": {"base", "protocol", "solver", "config", "netlists", "eye", "analysis", "reports", "cli"},
    "python": {"base", "protocol", "solver", "config", "netlists", "eye", "analysis", "reports",
               "python"},
}
# netlists/traffic is the stimulus side of the protocol: it sits on base and protocol alone.
SUBLAYERS = {"netlists/traffic": {"base", "protocol", "netlists/traffic"}}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of(rel: str):
    for sub in SUBLAYERS:
        if rel.startswith(sub + "/"):
            return sub
    top = rel.split("/", 1)[0]
    return top if top in ALLOWED else None


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    bad = []
    for path in sorted(root.rglob("*")):
        if path.suffix not in (".h", ".cpp", ".in") or not path.is_file():
            continue
        rel = path.relative_to(root).as_posix()
        src = layer_of(rel)
        if src is None:
            continue
        allowed = SUBLAYERS.get(src) or ALLOWED[src]
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            dst = layer_of(m.group(1))
            if dst is None:
                continue
            ok = dst in allowed or (dst.split("/")[0] in allowed and src not in SUBLAYERS)
            if not ok:
                bad.append(f"{rel}:{n}: error: layer '{src}' may not include \"{m.group(1)}\" "
                           f"(layer '{dst}'); allowed: {', '.join(sorted(allowed))}")
    for b in bad:
        print(b)
    print(f"layers: {len(bad)} violation(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
