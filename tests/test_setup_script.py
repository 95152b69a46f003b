"""The two-command set-up (./evinr): the environment is created when missing, left alone when up to
date, refreshed when its requirements change; CI runs exactly the README's test command.

The environment here is a scratch virtual environment built from a requirements file without
packages (EVINR_VENV, EVINR_REQUIREMENTS), so the test exercises the script's logic in seconds
without installing the project's pins a second time."""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "evinr"


def _evinr(*args, env):
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, env=env, timeout=300, stdin=subprocess.DEVNULL)


@pytest.fixture
def scratch_env(tmp_path):
    requirements = tmp_path / "requirements.txt"
    requirements.write_text("# no packages: the script's logic only\n")
    env = {**os.environ, "EVINR_VENV": str(tmp_path / "venv"), "EVINR_REQUIREMENTS": str(requirements),
           "EVINR_PYTHON": sys.executable}
    env.pop("VIRTUAL_ENV", None)
    return env, tmp_path / "venv", requirements


def test_environment_created_reused_and_refreshed(scratch_env):
    env, venv, requirements = scratch_env
    r = _evinr("status", env=env)
    assert r.returncode == 1 and "missing" in r.stdout

    r = _evinr("env", env=env)
    assert r.returncode == 0, r.stderr
    assert "creating the environment" in r.stderr and (venv / "bin" / "python").exists()
    r = _evinr("status", env=env)
    assert r.returncode == 0 and "fresh" in r.stdout

    r = _evinr("env", env=env)   # up to date: nothing is installed again
    assert r.returncode == 0 and r.stderr == ""

    requirements.write_text(requirements.read_text() + "# a pin changed\n")
    r = _evinr("status", env=env)
    assert r.returncode == 1 and "stale" in r.stdout
    r = _evinr("env", env=env)
    assert r.returncode == 0 and "refreshing" in r.stderr and "creating" not in r.stderr
    assert _evinr("status", env=env).returncode == 0


def test_commands_run_inside_the_environment(scratch_env):
    env, venv, _ = scratch_env
    r = _evinr("run", "python", "-c", "import sys; print(sys.prefix)", env=env)
    assert r.returncode == 0, r.stderr
    assert Path(r.stdout.strip().splitlines()[-1]).resolve() == venv.resolve()


def test_failed_install_leaves_the_environment_stale(scratch_env, tmp_path):
    env, venv, requirements = scratch_env
    requirements.write_text(f"-r {tmp_path / 'does_not_exist.txt'}\n")   # pip fails without the network
    r = _evinr("env", env=env)
    assert r.returncode == 2 and "pip install -r" in r.stderr and "./evinr env" in r.stderr
    assert "fresh" not in _evinr("status", env=env).stdout   # the next command tries again


def test_unknown_command_prints_usage():
    r = subprocess.run([str(SCRIPT), "frobnicate"], capture_output=True, text=True, stdin=subprocess.DEVNULL)
    assert r.returncode == 2 and "unknown command 'frobnicate'" in r.stderr and "./evinr test" in r.stderr


def test_ci_runs_the_readme_test_command():
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Run the tests", 1)[1].split("\n## ", 1)[0]
    command = re.search(r"```bash\n(.+?)\n", section).group(1).strip()
    ci_lines = [ln.strip() for ln in (ROOT / ".ci" / "run").read_text().splitlines()
                if ln.strip() and not ln.lstrip().startswith("#")]
    assert command == "./evinr test" and ci_lines[-1] == command
    assert "set -euo pipefail" in ci_lines   # a failing step (apt-get, pip, a test) fails CI
