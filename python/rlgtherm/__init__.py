"""The package rlgtherm: the C++ extension rlgtherm._core (python/*.cpp; its classes and
functions name themselves rlgtherm's) with its type stubs (__init__.pyi, py.typed). Everything
public is the extension's."""
from rlgtherm import _core
from rlgtherm._core import *  # noqa: F401,F403 (the API is the extension's: docs/python.md)

__doc__ = _core.__doc__
__version__ = _core.__version__
__all__ = sorted(name for name in vars(_core) if not name.startswith("_"))
