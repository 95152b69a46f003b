"""The command line, the demo and the reconstruct job (they never import viz or teaching)."""
from .cli import main   # light: the command's guard starts before anything heavy is imported

_HOME = {"run_demo": "demo", "run_reconstruct": "recon_job", "RunOptions": "options", "run_batch": "batch"}


def __getattr__(name):
    import importlib

    if name in _HOME:
        return getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)
    if name == "recon_job":   # notebook 11 calls its steps as ev.apps.recon_job.X
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = ["main", "run_demo", "run_reconstruct", "RunOptions", "run_batch"]
