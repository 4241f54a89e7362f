# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Development shim: ``import pointform`` from the repository root loads the package that the
build made in build/<preset>/python/pointform (the module ``_pointform`` and its type stub).
bash scripts/quickstart.sh and bash scripts/test.sh build it with the release preset; set
POINTFORM_BUILD to another build folder (e.g. build/debug) to use that one instead. From
elsewhere, put build/release/python on PYTHONPATH."""

import os as _os

_root = _os.path.dirname(_os.path.dirname(_os.path.abspath(__file__)))
_build = _os.environ.get("POINTFORM_BUILD", _os.path.join(_root, "build", "release"))
_package = _os.path.join(_os.path.abspath(_build), "python", "pointform")
if not _os.path.isfile(_os.path.join(_package, "__init__.py")):
    raise ImportError(
        f"pointform is not built in {_build}: run `bash scripts/quickstart.sh` (or "
        "`cmake --preset release && cmake --build --preset release --target pointform_python`) "
        "from the repository root")
# Submodules (the extension module _pointform) load from the build folder.
__path__ = [_package]
__file__ = _os.path.join(_package, "__init__.py")
with open(__file__, encoding="utf-8") as _init:
    exec(compile(_init.read(), __file__, "exec"))
