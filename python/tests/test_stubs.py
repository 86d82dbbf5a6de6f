"""The type stubs (python/rlgtherm/__init__.pyi) match the module: the same public names, and for
every function, overload, method and property the same parameters (names, order, kind, which have
defaults) as the signatures pybind11 writes at the head of each docstring. Types are not compared
(the stubs say more than pybind11's `object`); the package ships the stubs and py.typed (PEP 561)."""
import ast
import re
from pathlib import Path

import pytest

import rlgtherm

PACKAGE = Path(rlgtherm.__file__).parent
STUBS = ast.parse((PACKAGE / "__init__.pyi").read_text())


def split_top_level(text):
    """text split at the commas outside brackets and quotes."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


def runtime_signatures(obj, name):
    """Each overload's parameters from pybind11's docstring: [(name, kind, has_default)], kind
    'arg', 'kwonly', '*args' or '**kwargs'; self left out."""
    doc = obj.__doc__ or ""
    # One head line, or "name(*args, **kwargs)" (no "->") then "1. name(...) -> ..." per overload.
    heads = re.findall(rf"^(?:\d+\. )?{re.escape(name)}\((.*)\) -> .*$", doc, flags=re.M)
    signatures = []
    for head in heads:
        params, kind = [], "arg"
        for p in split_top_level(head):
            if p == "*":
                kind = "kwonly"
            elif p.startswith("**"):
                params.append((p[2:].split(":")[0], "**kwargs", False))
            elif p.startswith("*"):
                params.append((p[1:].split(":")[0], "*args", False))
                kind = "kwonly"
            else:
                params.append((re.split(r"[:=]", p)[0].strip(), kind, "=" in p))
        if params and params[0][0] in ("self", "arg0"):
            params = params[1:]
        signatures.append(params)
    return signatures


def is_static(f):
    return any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in f.decorator_list)


def stub_signature(f, method):
    a = f.args
    positional = a.posonlyargs + a.args
    defaults = [False] * (len(positional) - len(a.defaults)) + [True] * len(a.defaults)
    params = [(p.arg, "arg", d) for p, d in zip(positional, defaults)]
    if method and not is_static(f):  # a static method has no self to leave out
        params = params[1:]
    if a.vararg:
        params.append((a.vararg.arg, "*args", False))
    params += [(p.arg, "kwonly", d is not None) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    if a.kwarg:
        params.append((a.kwarg.arg, "**kwargs", False))
    return params


def is_property(f):
    return any(isinstance(d, ast.Name) and d.id == "property" for d in f.decorator_list)


def is_setter(f):
    return any(isinstance(d, ast.Attribute) and d.attr == "setter" for d in f.decorator_list)


def stub_functions(body):
    """name -> [signature of each overload] of the defs in `body`, and properties -> settable."""
    functions, properties = {}, {}
    for node in body:
        if isinstance(node, ast.FunctionDef):
            if is_property(node):
                properties.setdefault(node.name, False)
            elif is_setter(node):
                properties[node.name] = True
            else:
                functions.setdefault(node.name, []).append(node)
    return functions, properties


STUB_FUNCTIONS, _ = stub_functions(STUBS.body)
STUB_CLASSES = {n.name: n for n in STUBS.body if isinstance(n, ast.ClassDef)}
# Methods a class defines in the binding that the stubs must list (reprs are left out: every object has one).
DUNDERS = {"__init__", "__getitem__", "__len__", "__iter__", "__contains__"}


def test_the_package_is_typed():
    assert (PACKAGE / "py.typed").exists() and (PACKAGE / "__init__.pyi").exists()


def test_the_stubs_name_every_public_name_and_no_other():
    stubbed = {n for n in [*STUB_FUNCTIONS, *STUB_CLASSES] if not n.startswith("_")}
    assert stubbed == set(rlgtherm.__all__)


@pytest.mark.parametrize("name", sorted(STUB_FUNCTIONS))
def test_a_functions_stub_has_the_modules_parameters(name):
    stubs = [stub_signature(f, method=False) for f in STUB_FUNCTIONS[name]]
    assert stubs == runtime_signatures(getattr(rlgtherm, name), name)


@pytest.mark.parametrize("name", sorted(STUB_CLASSES))
def test_a_classs_stub_has_the_modules_methods_and_properties(name):
    cls = getattr(rlgtherm, name)
    functions, properties = stub_functions(STUB_CLASSES[name].body)
    members = {k: v.__func__ if isinstance(v, staticmethod) else v  # its function has the docstring
               for k, v in vars(cls).items() if not k.startswith("_") or k in DUNDERS}
    runtime_properties = {k: v.fset is not None for k, v in members.items() if isinstance(v, property)}
    assert properties == runtime_properties
    # A class without a constructor (Gyro: load_gyro makes them) has an __init__ without a signature.
    runtime_methods = {k: v for k, v in members.items()
                       if not isinstance(v, property) and runtime_signatures(v, k)}
    assert set(functions) == set(runtime_methods)
    for method, overloads in functions.items():
        assert [stub_signature(f, method=True) for f in overloads] == \
            runtime_signatures(runtime_methods[method], method), f"{name}.{method}"
