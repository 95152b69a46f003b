import os

# Fast mode for every test and every notebook kernel that nbval starts (kernels inherit the
# environment). Run `EVINR_FAST=0 python -m pytest` to execute the notebooks at full size.
os.environ.setdefault("EVINR_FAST", "1")
os.environ.setdefault("MPLBACKEND", "Agg")
# torch's OpenMP threads otherwise spin while waiting for each other; on a busy 2-core machine that
# made a fast-mode notebook 7x slower (92 s against 14 s, same load)
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
