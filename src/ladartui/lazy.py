"""Package attributes that import their module on first use (PEP 562)."""

import importlib


def lazy_getattr(package: str, exports: dict, namespace: dict):
    """A module ``__getattr__`` that loads ``exports[name]`` and caches the value in ``namespace``."""

    def __getattr__(name):
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        namespace[name] = value
        return value

    return __getattr__
