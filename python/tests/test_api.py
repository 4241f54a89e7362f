# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""The package's surface: every public name documented and declared in the type stub."""

import ast
import inspect
import os

import pointform


def public(obj):
    return [name for name in dir(obj) if not name.startswith("_")]


def stub_names():
    stub = os.path.join(os.path.dirname(pointform.__file__), "_pointform.pyi")
    tree = ast.parse(open(stub, encoding="utf-8").read())
    names, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        if isinstance(node, ast.ClassDef):
            members[node.name] = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        if isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    return {n for n in names if not n.startswith("_")}, members


def test_every_public_name_has_a_docstring_and_a_stub():
    names, members = stub_names()
    exported = set(public(pointform)) - {"annotations"}
    assert exported == names, f"stub and module differ: {exported ^ names}"
    for name in exported:
        obj = getattr(pointform, name)
        if callable(obj):
            assert obj.__doc__ and len(obj.__doc__.strip()) > 20, name
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for member in public(obj):
                attribute = getattr(obj, member)
                assert attribute.__doc__ and attribute.__doc__.strip(), f"{name}.{member}"
                assert member in members[name], f"{name}.{member} is not in the stub"


def test_exception_hierarchy():
    assert issubclass(pointform.InvalidInput, ValueError)
    assert issubclass(pointform.InvalidInput, pointform.Error)
    assert issubclass(pointform.IoError, OSError)
    assert issubclass(pointform.IoError, pointform.Error)
    assert issubclass(pointform.Error, RuntimeError)
    for name in ("SolverError", "TopologyError", "Cancelled"):
        assert issubclass(getattr(pointform, name), pointform.Error)
