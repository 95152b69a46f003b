"""pytest's settings for the notebooks run under nbval (``python -m pytest``; the README's test command).

A notebook's kernel inherits this process's environment. Notebook 11 writes its exports into a
``tempfile.mkdtemp`` scratch folder, as a reader's session would, and leaves it for the reader to open:
under the test suite that was one more folder in /tmp on every run. Every kernel started from here on
makes its temporary folders inside one folder of this run's own, removed when the run ends.
"""
import atexit
import os
import shutil
import tempfile

_SCRATCH = tempfile.mkdtemp(prefix="evinr_nbval_")
os.environ["TMPDIR"] = _SCRATCH
atexit.register(shutil.rmtree, _SCRATCH, ignore_errors=True)
