"""The command line, the demo and the reconstruct job (they never import viz or teaching)."""
# every name is imported on first use, the command line's too: importing the package never imports cli, so
# `python -m evinr_lite.apps.cli` runs it without runpy's warning about a module imported twice
_HOME = {"main": "cli", "run_demo": "demo", "run_reconstruct": "recon_job", "RunOptions": "options", "run_batch": "batch"}


def __getattr__(name):
    import importlib

    if name in _HOME:
        return getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)
    if name == "recon_job":   # notebook 11 calls its steps as ev.apps.recon_job.X
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = ["main", "run_demo", "run_reconstruct", "RunOptions", "run_batch"]
