"""``python -m benchmarks``: run every speed benchmark and print one table (see run_all.py)."""
import sys

from benchmarks.run_all import main

sys.exit(main())
