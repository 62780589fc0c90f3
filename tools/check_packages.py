#!/usr/bin/env python3
"""Fails when the build uses a Debian package that tools/setup.sh does not install.

    python3 tools/check_packages.py [BUILD_DIR]      (default: build; run after tools/setup.sh)

What the configure and build steps read, outside the source and build trees:
  * configure: every CMake file that ran (cmake --trace-format=json-v1 --trace-expand on a
    re-configure of BUILD_DIR: CMake's own modules and each package's Config files), every
    existing file named in a traced command's arguments (the files an imported target must have,
    e.g. OpenImageIO's bin/iconvert from openimageio-tools), and every absolute path stored in
    CMakeCache.txt (find_library/find_path/find_program results: KLU, ngspice, MPI, Python...);
  * compile: every header each object file included (the compiler's dependency files: *.d for the
    Makefile generator, `ninja -t deps` for Ninja);
  * link: every absolute path on the link lines, and the shared libraries the built programs and
    libraries load (ldd).
Each file is mapped to its package with `dpkg -S` (symlinks resolved, /lib and /usr/lib both
tried, for bookworm's merged /usr). A package is allowed when setup.sh's PACKAGES lists it, when
a listed package depends on it (Depends/Pre-Depends, recursively, through virtual packages and
every alternative of an 'a | b'), or when Debian installs it on every system (Essential: yes or
Priority: required, and their dependencies). Anything else fails, naming the package and one file
that needed it; so does a file under /usr/local or /opt, or a header or library that no package
owns (a hand-installed dependency a fresh machine would not have).
"""
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def setup_packages():
    text = open(os.path.join(ROOT, "tools", "setup.sh")).read()
    m = re.search(r"^PACKAGES=\((.*?)^\)", text, re.S | re.M)
    if not m:
        sys.exit("check_packages: no PACKAGES=( ... ) in tools/setup.sh")
    body = re.sub(r"#.*", "", m.group(1))
    return set(body.split())


def installed_packages():
    """name -> (priority, essential, depends) for every installed package."""
    out = subprocess.run(
        ["dpkg-query", "-W", "-f",
         "${Package}\t${Status}\t${Priority}\t${Essential}\t${Depends}, ${Pre-Depends}\t${Provides}\n"],
        check=True, capture_output=True, text=True).stdout
    pkgs, providers = {}, {}
    for line in out.splitlines():
        name, status, prio, essential, deps, provides = (line.split("\t") + [""] * 6)[:6]
        if not status.endswith(" installed"):
            continue
        alts = []
        for group in deps.split(","):
            names = [re.sub(r"[\s(:].*", "", a.strip()) for a in group.split("|")]
            alts.extend(n for n in names if n)
        pkgs[name] = (prio, essential == "yes", alts)
        for p in provides.split(","):
            p = re.sub(r"[\s(].*", "", p.strip())
            if p:
                providers.setdefault(p, []).append(name)
    return pkgs, providers


def closure(roots, pkgs, providers):
    seen, todo = set(), list(roots)
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.add(p)
        todo.extend(providers.get(p, []))
        if p in pkgs:
            todo.extend(pkgs[p][2])
    return seen


def outside(path, build):
    return not (path.startswith(ROOT + "/") or path.startswith(build + "/") or
                path.startswith(("/proc/", "/dev/", "/sys/", "/tmp/")))


def configure_files(build):
    """CMake files that ran during a re-configure, and absolute paths in the cache."""
    files = set()
    with tempfile.TemporaryDirectory() as tmp:
        trace = os.path.join(tmp, "trace.json")
        subprocess.run(["cmake", "-S", ROOT, "-B", build, "--trace-format=json-v1",
                        "--trace-expand", "--trace-redirect=" + trace], check=True,
                       stdout=subprocess.DEVNULL)
        with open(trace) as f:
            for line in f:
                try:
                    entry = json.loads(line)
                except ValueError:
                    continue
                if "file" in entry and os.path.isfile(entry["file"]):  # not "<file>:58:EVAL"
                    files.add(entry["file"])
                # Files named in the commands' arguments: the imported targets' files that a
                # package's Targets file checks for (OpenImageIO's bin/iconvert needs
                # openimageio-tools), libraries and programs found.
                for arg in entry.get("args", []):
                    for tok in re.split(r"[;\s]", arg):
                        if tok.startswith("/") and os.path.isfile(tok):
                            files.add(tok)
    for line in open(os.path.join(build, "CMakeCache.txt")):
        if line.startswith(("//", "#")) or "=" not in line:
            continue
        value = line.split("=", 1)[1].strip()
        for tok in re.split(r"[;\s]", value):
            if tok.startswith("/") and os.path.isfile(tok):
                files.add(tok)
    return files


def compile_files(build):
    files = set()
    if os.path.exists(os.path.join(build, "build.ninja")):
        out = subprocess.run(["ninja", "-C", build, "-t", "deps"], check=True,
                             capture_output=True, text=True).stdout
        for line in out.splitlines():
            if line.startswith("    "):
                files.add(line.strip())
    for d, _, names in os.walk(build):
        for n in names:
            if n.endswith(".d") or n == "compiler_depend.make" or n == "link.txt" or n == "build.ninja":
                text = open(os.path.join(d, n), errors="replace").read()
                for tok in re.split(r"[\s\\:]+", text):
                    if tok.startswith("/") and os.path.isfile(tok):
                        files.add(tok)
    return files


def runtime_files(build):
    files = set()
    for d, _, names in os.walk(build):
        if "CMakeFiles" in d:
            continue
        for n in names:
            p = os.path.join(d, n)
            if os.path.isfile(p) and os.access(p, os.X_OK) and (n.endswith(".so") or "." not in n):
                with open(p, "rb") as f:
                    if f.read(4) != b"\x7fELF":
                        continue
                out = subprocess.run(["ldd", p], capture_output=True, text=True).stdout
                files.update(m.group(1) for m in re.finditer(r"=> (/\S+)", out))
    return files


def owners(paths):
    """path -> package for each path dpkg knows (symlinks and /lib vs /usr/lib tried)."""
    candidates = {}
    for p in paths:
        c = [p, os.path.realpath(p)]
        for q in list(c):
            if q.startswith("/usr/lib/") or q.startswith("/usr/bin/") or q.startswith("/usr/sbin/"):
                c.append(q[4:])
            elif q.startswith(("/lib/", "/bin/", "/sbin/")):
                c.append("/usr" + q)
        candidates[p] = list(dict.fromkeys(c))
    every = sorted({q for c in candidates.values() for q in c})
    owner = {}
    for i in range(0, len(every), 500):
        out = subprocess.run(["dpkg", "-S"] + every[i:i + 500], capture_output=True, text=True).stdout
        for line in out.splitlines():
            pkg, _, path = line.partition(": ")
            if path and "," not in pkg and not pkg.startswith("diversion by"):
                owner[path] = pkg.split(":")[0]
    return {p: next((owner[q] for q in c if q in owner), None) for p, c in candidates.items()}


def main():
    build = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build"))
    if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
        sys.exit(f"check_packages: {build} is not a configured build tree (run tools/setup.sh)")
    listed = setup_packages()
    pkgs, providers = installed_packages()
    base = {p for p, (prio, essential, _) in pkgs.items() if essential or prio == "required"}
    allowed = closure(listed | base, pkgs, providers)

    files = {f for f in configure_files(build) | compile_files(build) | runtime_files(build)
             if outside(f, build)}
    problems = []
    used = {}
    for path, pkg in sorted(owners(files).items()):
        if path.startswith(("/usr/local/", "/opt/")):
            problems.append(f"{path}: not from a Debian package (under /usr/local or /opt)")
        elif pkg is None:
            if path.startswith(("/usr/include/", "/usr/lib/", "/lib/", "/usr/share/cmake")):
                problems.append(f"{path}: no Debian package owns it (installed by hand?)")
        else:
            used.setdefault(pkg, path)
    for pkg, path in sorted(used.items()):
        if pkg not in allowed:
            problems.append(f"package {pkg} is used (e.g. {path}) but tools/setup.sh does not "
                            "install it: add it to PACKAGES")
    unlisted_missing = sorted(p for p in listed if p not in pkgs)
    for p in unlisted_missing:
        problems.append(f"package {p} is in tools/setup.sh PACKAGES but not installed")
    print(f"check_packages: {len(files)} files outside the tree from {len(used)} packages; "
          f"{len(listed)} listed in setup.sh, {len(allowed)} allowed with dependencies and "
          "required/essential packages")
    for p in problems:
        print("check_packages: error: " + p, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
