#!/usr/bin/env bash
# CTest python.install: `cmake --install BUILD --prefix STAGE` into a temporary prefix, then the
# notebook example run by /usr/bin/python3 from a folder outside the repository with an empty
# environment (env -i): the module imported from STAGE's site folder, every function called on
# dict specs and compared with STAGE's bin/isolink (python/README.md, "Installing").
#   install_test.sh BUILD SITE_DIR NOTEBOOK   (SITE_DIR: ISOLINK_PYTHON_INSTALL_DIR)
set -euo pipefail
build=$(realpath "$1") site_rel=$2 notebook=$(realpath "$3")
stage=$(mktemp -d /tmp/isolink-install-XXXXXX)
trap 'rm -rf "$stage"' EXIT
cmake --install "$build" --prefix "$stage" >/dev/null
fail() { echo "install_test: $*" >&2; exit 1; }
[ -x "$stage/bin/isolink" ] || fail "no bin/isolink under the prefix"
plugin=$(find "$stage/lib/isolink" -name '*.so' | head -n 1)
[ -n "$plugin" ] || fail "no image plug-in under lib/isolink"
site="$stage/$site_rel"
ls "$site"/isolink.cpython-*.so >/dev/null || fail "no module in $site"
[ -f "$site/isolink.pyi" ] || fail "no isolink.pyi stub in $site"
# Under the default prefix /usr/local the same folder is on the system Python's path with nothing
# set: the README's `import isolink` after tools/setup.sh (which installs there).
env -i /usr/bin/python3 -c "import sys; d = '/usr/local/$site_rel'; \
assert d in sys.path, d + ' is not on sys.path: ' + str(sys.path)" || fail "site folder not searched"
cd "$stage"  # outside the repository
# The notebook: nothing in the environment; the module found through the prefix's site folder.
# (First on the path: an isolink that tools/setup.sh installed under /usr/local must not answer.)
env -i /usr/bin/python3 -c "import sys, runpy; sys.path.insert(0, sys.argv[1]); \
import isolink; assert isolink.__file__.startswith(sys.argv[1]), isolink.__file__; \
sys.argv = sys.argv[2:]; runpy.run_path(sys.argv[0], run_name='__main__')" \
  "$site" "$notebook" --check-cli "$stage/bin/isolink"
