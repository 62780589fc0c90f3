"""isolink.pyi (the stub editors read) has every function of the module with the same parameters,
and each function's docstring documents its arguments and return shape."""
import ast
import os
import pathlib
import re

import isolink

STUB = pathlib.Path(__file__).resolve().parent.parent / "isolink.pyi"


def stub_functions():
    tree = ast.parse(STUB.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            a = node.args
            out[node.name] = ([x.arg for x in a.posonlyargs + a.args], [x.arg for x in a.kwonlyargs])
    return out


def module_functions():
    """name -> (positional, keyword-only) parameter names, from pybind11's signature line."""
    out = {}
    for name in dir(isolink):
        f = getattr(isolink, name)
        if name.startswith("_") or not callable(f) or isinstance(f, type):
            continue
        sig = f.__doc__.splitlines()[0]
        params = re.match(rf"{name}\((.*)\) ->", sig).group(1)
        pos, kw, seen_star = [], [], False
        for p in re.split(r", (?![^\[]*\])", params):
            if p == "*":
                seen_star = True
                continue
            (kw if seen_star else pos).append(p.split(":")[0])
        out[name] = (pos, kw)
    return out


def test_stub_matches_the_module():
    mod, stub = module_functions(), stub_functions()
    assert sorted(mod) == sorted(stub)
    for name in mod:
        assert mod[name] == stub[name], name
    assert sorted(mod) == ["check", "compare", "load_spec", "noise", "pack", "run", "sim", "stress", "sweep",
                           "worst"]


def test_docstrings_give_arguments_and_returns():
    for name, (pos, kw) in module_functions().items():
        doc = getattr(isolink, name).__doc__
        assert "Args:" in doc and "Returns:" in doc, name
        for p in pos + kw:
            assert re.search(rf"^\s+(\w+, )*{p}(, \w+)*:", doc, re.M), f"{name}: {p} undocumented"


def test_stub_sits_beside_the_module():
    assert (pathlib.Path(isolink.__file__).parent / "isolink.pyi").read_text() == STUB.read_text()
    assert os.path.isfile(isolink.__file__)
