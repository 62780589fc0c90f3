#!/usr/bin/env python3
"""Fails when a README or a page of docs/ names a repository path that does not exist.

A newcomer follows these paths from the README to the code ("Where things are", docs/physics.md
section 10, each folder's README); a file renamed without its citations breaks that tour. A path
is a word like `eye/metrics.cpp` or `netlists/link/README.md` (a top-level folder of the
repository, then a file name with an extension) or a Markdown link target; it must exist relative
to the page's own folder or to the repository root. Placeholders (NAME, NN) and generated files
(`*.cpp` made from a `.cpp.in`) are accepted.
Usage: check_doc_paths.py [SOURCE_DIR]
"""
import pathlib
import re
import subprocess
import sys

TOP = ("base", "protocol", "solver", "config", "netlists", "eye", "analysis", "reports", "cli",
       "python", "tests", "tools", "bench", "docs", "cmake")
PATH = re.compile(r"(?<![\w/.-])((?:%s)/[\w./*-]+\.[a-z]{1,4})\b" % "|".join(TOP))
# Paths of other projects that a page cites as theirs.
EXTERNAL = {"tests/general/rc.cir"}  # ngspice's own test deck (docs/solver.md)
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def tracked_pages(root: pathlib.Path):
    """The .md files git tracks, or None outside a git work tree or without git (an exported
    tree, as the README's bare-root recipe makes with `git archive`)."""
    try:
        out = subprocess.run(["git", "ls-files", "*.md"], cwd=root, capture_output=True, text=True)
    except OSError:
        return None
    return out.stdout.split() if out.returncode == 0 else None


def pages(root: pathlib.Path):
    names = tracked_pages(root)
    if names is None:  # every page outside build folders and reports/out
        names = [p.relative_to(root).as_posix() for p in root.rglob("*.md")
                 if not p.relative_to(root).parts[0].startswith(("build", ".git"))]
    for name in names:
        parts = name.split("/")
        # The top README, docs/, and each folder's own README (not data folders' notes).
        if name == "README.md" or parts[0] == "docs" or (parts[-1] == "README.md" and
                                                          len(parts) <= 3 and parts[0] in TOP):
            yield root / name


def exists(root: pathlib.Path, page: pathlib.Path, path: str) -> bool:
    if path in EXTERNAL or any(tok in path for tok in ("NAME", "NN", "*", "<")):
        return True
    for base in (page.parent, root):
        p = base / path
        if p.exists() or (p.suffix == ".cpp" and p.with_suffix(".cpp.in").exists()):
            return True
    return False


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    bad = []
    for page in pages(root):
        rel = page.relative_to(root).as_posix()
        for n, line in enumerate(page.read_text(errors="replace").splitlines(), 1):
            found = PATH.findall(line) + [t for t in LINK.findall(line) if "://" not in t]
            for path in found:
                if not exists(root, page, path.rstrip(".")):
                    bad.append(f"{rel}:{n}: error: '{path}' does not exist")
    for b in bad:
        print(b)
    print(f"doc paths: {len(bad)} missing" if bad else "doc paths: every cited path exists")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
