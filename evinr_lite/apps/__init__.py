"""The command line, the demo and the reconstruct job (they never import viz or teaching)."""
from .cli import main
from .demo import run_demo
from .recon_job import run_reconstruct

__all__ = ["main", "run_demo", "run_reconstruct"]
