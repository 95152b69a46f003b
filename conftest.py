import os

# Fast mode for every test and every notebook kernel that nbval starts (kernels inherit the
# environment). Run `EVINR_FAST=0 python -m pytest` to execute the notebooks at full size.
os.environ.setdefault("EVINR_FAST", "1")
os.environ.setdefault("MPLBACKEND", "Agg")
