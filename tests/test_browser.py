"""What a reader sees: notebook 01 in JupyterLab in headless Chromium, and the rendered gallery.

JupyterLab runs on 127.0.0.1 (a free port, a token, a temporary root folder with a copy of the
notebook, temporary settings). Debian's Chromium (``/usr/bin/chromium``, ``/usr/bin/chromedriver``;
never a downloaded browser), driven by selenium, opens the notebook, runs all cells in fast mode
with the sliders kept (``EVINR_LIVE_WIDGETS=1``), checks that no cell shows an error, moves one
slider of the first ``interact`` widget and checks that its figure changed and that it is still
the only figure of that widget. Then it builds the gallery of the same notebook
(tools/render_notebooks.py) and checks that the index and the page load their images.

Screenshots go to ``test-artefacts/browser/``. Bounded to about two minutes (DEADLINE_S). Without
Chromium it skips, naming the install command; under CI (CI=true) it fails instead.
"""
import importlib.util
import json
import os
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "notebooks" / "01_event_generation_1d.ipynb"
ARTEFACTS = ROOT / "test-artefacts" / "browser"
DEADLINE_S = 150          # the whole test, seconds
INSTALL = "apt-get install -y chromium chromium-driver && pip install selenium==4.51.0"
CHROME_FLAGS = ("--headless=new", "--no-sandbox", "--disable-background-networking", "--disable-component-update",
                "--no-first-run", "--disable-default-apps", "--disable-sync", "--disable-gpu",
                "--disable-dev-shm-usage", "--window-size=1400,1100")


def _browser_or_skip():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    problem = None
    if not chromium or not driver:
        problem = f"Debian's chromium and chromium-driver are not installed ({INSTALL})"
    else:
        try:
            import selenium  # noqa: F401
        except ImportError:
            problem = f"selenium is not installed ({INSTALL})"
    if problem:
        if os.environ.get("CI"):
            pytest.fail(f"browser test cannot run in CI: {problem}; .ci/run installs them")
        pytest.skip(problem)
    return chromium, driver


class Deadline:
    def __init__(self, seconds):
        self.end = time.monotonic() + seconds

    def left(self):
        return self.end - time.monotonic()

    def wait(self, what, check, poll=0.5):
        """Poll check() until it returns something truthy; fail naming ``what`` at the deadline."""
        last = None
        while self.left() > 0:
            last = check()
            if last:
                return last
            time.sleep(poll)
        pytest.fail(f"timed out ({DEADLINE_S} s for the whole test) waiting for {what}; last state: {last!r}")


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def jupyterlab(tmp_path):
    """A JupyterLab server on 127.0.0.1 serving a folder with a copy of the notebook."""
    root = tmp_path / "root"
    root.mkdir()
    shutil.copy(NOTEBOOK, root / NOTEBOOK.name)
    settings = tmp_path / "lab-settings" / "@jupyterlab" / "apputils-extension"
    settings.mkdir(parents=True)
    (settings / "notification.jupyterlab-settings").write_text(json.dumps({"fetchNews": "false",
                                                                          "checkForUpdates": False}))
    port, token = _free_port(), secrets.token_hex(16)
    env = {**os.environ, "EVINR_FAST": "1", "EVINR_LIVE_WIDGETS": "1",
           "MPLBACKEND": "module://matplotlib_inline.backend_inline",
           "JUPYTER_CONFIG_DIR": str(tmp_path / "config"), "JUPYTER_RUNTIME_DIR": str(tmp_path / "runtime"),
           "JUPYTERLAB_SETTINGS_DIR": str(tmp_path / "lab-settings"),
           "JUPYTERLAB_WORKSPACES_DIR": str(tmp_path / "workspaces")}
    env.pop("PYTEST_CURRENT_TEST", None)
    log = open(tmp_path / "jupyterlab.log", "w")
    server = subprocess.Popen(
        [sys.executable, "-m", "jupyterlab", "--no-browser", "--ServerApp.ip=127.0.0.1", f"--ServerApp.port={port}",
         "--ServerApp.port_retries=0", f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={root}",
         "--LabApp.expose_app_in_browser=True", "--LabApp.news_url=", "--LabApp.extension_manager=readonly",
         "--ServerApp.terminals_enabled=False", "--allow-root"],
        env=env, stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, cwd=root)
    base = f"http://127.0.0.1:{port}"
    try:
        t0 = time.monotonic()
        while True:
            try:
                with urllib.request.urlopen(f"{base}/api/status?token={token}", timeout=2) as r:
                    if r.status == 200:
                        break
            except OSError:
                pass
            if server.poll() is not None or time.monotonic() - t0 > 60:
                log.flush()
                pytest.fail(f"JupyterLab did not start: {(tmp_path / 'jupyterlab.log').read_text()[-2000:]}")
            time.sleep(0.5)
        yield {"url": f"{base}/lab/tree/{NOTEBOOK.name}?token={token}", "log": tmp_path / "jupyterlab.log"}
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        log.close()


@pytest.fixture
def chromium(tmp_path):
    binary, driver_path = _browser_or_skip()
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    os.environ.setdefault("SE_OFFLINE", "true")   # selenium never looks for (or downloads) a driver
    options = Options()
    options.binary_location = binary
    for flag in CHROME_FLAGS + (f"--user-data-dir={tmp_path / 'chromium-profile'}",):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(executable_path=driver_path), options=options)
    driver.set_page_load_timeout(60)
    driver.set_script_timeout(60)
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    try:
        yield driver
    finally:
        driver.quit()


NOTEBOOK_STATE = """
const app = window.jupyterapp;
const nb = app && app.shell.currentWidget;
if (!nb || !nb.content || !nb.sessionContext || !nb.sessionContext.session || !nb.sessionContext.session.kernel)
  return null;
const cells = nb.content.widgets;
const code = cells.filter(c => c.model.type === 'code');
const errors = [];
code.forEach(c => c.model.outputs.toJSON().forEach(o => {
  if (o.output_type === 'error') errors.push(o.ename + ': ' + o.evalue);
}));
return {kernel: nb.sessionContext.session.kernel.status, n_code: code.length,
        not_run: code.filter(c => c.model.executionCount === null).length,
        running: code.filter(c => c.promptNode && c.promptNode.textContent.includes('*')).length,
        errors: errors};
"""

WIDGET_STATE = """
const nb = window.jupyterapp.shell.currentWidget;
const cell = nb.content.widgets[arguments[0]];
const imgs = Array.from(cell.node.querySelectorAll('.jp-Cell-outputArea img'));
return {n_figures: imgs.length, src: imgs.length ? imgs[0].src : null,
        n_sliders: cell.node.querySelectorAll('.widget-slider .noUi-handle').length,
        text: cell.node.querySelector('.jp-Cell-outputArea').innerText};
"""

IMAGES_LOADED = """
const imgs = Array.from(document.images);
return {n: imgs.length, broken: imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src)};
"""


def _gallery(tmp_path):
    spec = importlib.util.spec_from_file_location("render_notebooks", ROOT / "tools" / "render_notebooks.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool.build(tmp_path / "site", only=[NOTEBOOK.stem], log=lambda *a, **k: None)


def test_notebook_in_jupyterlab_and_the_gallery(jupyterlab, chromium, tmp_path):
    from selenium.webdriver.common.keys import Keys

    deadline = Deadline(DEADLINE_S)
    driver = chromium
    driver.get(jupyterlab["url"])
    deadline.wait("the notebook and its kernel", lambda: (s := driver.execute_script(NOTEBOOK_STATE)) and
                  s["kernel"] == "idle" and s)
    driver.execute_script("window.jupyterapp.commands.execute('notebook:run-all-cells');")

    def finished():
        s = driver.execute_script(NOTEBOOK_STATE)
        return s if s and s["kernel"] == "idle" and not s["running"] and (s["errors"] or not s["not_run"]) else None

    deadline.wait("all cells to run", finished)
    time.sleep(1.0)   # idle between two cells is not the end: check again
    state = deadline.wait("all cells to run", finished)
    assert state["errors"] == [], f"cells show errors: {state['errors']}"
    assert state["not_run"] == 0 and state["n_code"] > 10

    index = driver.execute_script("""
        const cells = window.jupyterapp.shell.currentWidget.content.widgets;
        return cells.findIndex(c => c.model.type === 'code' && c.model.sharedModel.getSource().includes('interact(draw'));""")
    assert index >= 0, "notebook 01 has no interact(draw, ...) cell"
    show_widget = ("window.jupyterapp.shell.currentWidget.content.widgets[arguments[0]].node"
                   ".querySelector('.jp-Cell-outputArea').scrollIntoView({block: 'center'});")
    driver.execute_script(show_widget, index)
    before = deadline.wait("the interact widget's slider and figure",
                           lambda: (w := driver.execute_script(WIDGET_STATE, index)) and w["n_sliders"] and
                           w["n_figures"] and w)
    assert before["n_figures"] == 1, f"{before['n_figures']} figures in the interact cell before moving a slider"
    driver.execute_script(show_widget, index)
    driver.save_screenshot(str(ARTEFACTS / "01_run_all.png"))

    handle = driver.execute_script("return window.jupyterapp.shell.currentWidget.content.widgets[arguments[0]]"
                                   ".node.querySelector('.widget-slider .noUi-handle');", index)
    handle.click()
    for _ in range(3):
        handle.send_keys(Keys.ARROW_RIGHT)
    after = deadline.wait("the figure to be redrawn after moving the slider",
                          lambda: (w := driver.execute_script(WIDGET_STATE, index)) and w["src"] and
                          w["src"] != before["src"] and w)
    time.sleep(1.0)   # a second figure would arrive now if the redraw stacked instead of replacing
    after = driver.execute_script(WIDGET_STATE, index)
    driver.execute_script(show_widget, index)
    driver.save_screenshot(str(ARTEFACTS / "02_slider_moved.png"))
    assert after["n_figures"] == 1, f"{after['n_figures']} figures in the interact cell after moving a slider"
    assert after["src"] != before["src"]
    assert "Traceback" not in after["text"]
    assert driver.execute_script(NOTEBOOK_STATE)["errors"] == []

    # the gallery of the same notebook: the index and the page load every image
    site = Path(_gallery(tmp_path)["out"])
    for page, shot in (("index.html", "03_gallery_index.png"), (f"{NOTEBOOK.stem}.html", "04_gallery_page.png")):
        driver.get((site / page).as_uri())
        images = deadline.wait(f"the images of {page}", lambda: (s := driver.execute_script(IMAGES_LOADED)) and
                               s["n"] and not s["broken"] and s)
        assert images["n"] >= 1
        driver.save_screenshot(str(ARTEFACTS / shot))
    entry = json.loads((site / "gallery.json").read_text())["entries"][0]
    assert entry["n_figures"] >= 1 and entry["thumbnail"]
