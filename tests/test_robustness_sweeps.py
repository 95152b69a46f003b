"""benchmarks/robustness.py's sweep machinery on a tiny scene, and viz.plot_robustness by its properties."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from benchmarks import robustness as rb  # noqa: E402
from evinr_lite import viz  # noqa: E402
from evinr_lite.sim import scenes as sc  # noqa: E402
from evinr_lite.sim.zoo import ZooScene  # noqa: E402

TINY = ZooScene("tiny", "camera, 48x64, 1 s, clean sensor",
                lambda s, d: sc.MovingImageScene("camera", s, d, velocity=(20.0, 8.0), rotation=0.05, zoom=0.0),
                size=(48, 64), duration=1.0, seed=3)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def tiny_results():
    levels = {"keep": [0.1, 1.0], "noise_hz": [0.0, 3.0], "C_scale": [0.5, 1.0]}
    return rb.run_sweeps([TINY], ("integration", "hf"), levels, paper_levels=0, log=lambda *a, **k: None)


def test_sweeps_have_one_score_per_method_scene_and_level(tiny_results):
    r = tiny_results
    assert r["scenes"] == ["tiny"] and set(r["sweeps"]) == {"keep", "noise_hz", "C_scale"}
    for sw in r["sweeps"].values():
        for m in ("integration", "hf"):
            assert len(sw["scores"][m]["tiny"]) == 2 and all(s is not None for s in sw["scores"][m]["tiny"])
            for k in rb.METRICS:
                assert len(sw["means"][m][k]) == 2 and all(0 <= v <= 1 for v in sw["means"][m][k])


def test_the_clean_condition_is_one_run_shared_by_the_sweeps(tiny_results):
    sw = tiny_results["sweeps"]
    assert sw["keep"]["scores"]["hf"]["tiny"][1] is sw["noise_hz"]["scores"]["hf"]["tiny"][0]
    assert sw["keep"]["scores"]["hf"]["tiny"][1] is sw["C_scale"]["scores"]["hf"]["tiny"][1]


def test_thinning_and_noise_change_the_events_and_degrade_integration(tiny_results):
    keep, noise = tiny_results["sweeps"]["keep"], tiny_results["sweeps"]["noise_hz"]
    n_thin, n_all = (s["n_events"] for s in keep["scores"]["integration"]["tiny"])
    assert 0.07 * n_all < n_thin < 0.13 * n_all
    assert noise["scores"]["integration"]["tiny"][1]["n_events"] > n_all + 0.5 * 3.0 * 48 * 64
    mse = keep["means"]["integration"]["mse_none"]
    assert mse[0] > mse[1], f"integration with 10 % of the events should be worse: MSE {mse}"
    ssim = noise["means"]["integration"]["ssim_clahe"]
    assert ssim[1] < ssim[0], f"3 Hz of noise should lower integration's CLAHE-SSIM: {ssim}"


def test_thinning_is_seeded_and_nested():
    _, events, _, _ = rb.simulate(TINY)
    a, _ = rb.perturb(TINY, events, {**rb.CLEAN, "keep": 0.3})
    b, _ = rb.perturb(TINY, events, {**rb.CLEAN, "keep": 0.3})
    c, _ = rb.perturb(TINY, events, {**rb.CLEAN, "keep": 0.6})
    assert (a.t == b.t).all() and len(a) < len(c)
    assert set(zip(a.t, a.x, a.y)) <= set(zip(c.t, c.x, c.y))
    _, C = rb.perturb(TINY, events, {**rb.CLEAN, "C_scale": 2.0})
    assert C == pytest.approx(2 * TINY.C)
    with pytest.raises(ValueError, match="keep in"):
        rb.perturb(TINY, events, {**rb.CLEAN, "keep": 0.0})


def test_paper_subset_keeps_both_ends_and_the_clean_level():
    assert rb.paper_subset([0.5, 0.71, 1.0, 1.41, 2.0], 3, 1.0) == [0.5, 1.0, 2.0]
    assert rb.paper_subset([0.1, 0.2, 0.3, 0.5, 0.7, 1.0], 2, 1.0) == [0.1, 1.0]
    assert rb.paper_subset([0.0, 1.0, 3.0], 0, 0.0) == []


def test_unknown_sweep_is_refused():
    with pytest.raises(ValueError, match="unknown sweeps"):
        rb.run_sweeps([TINY], ("integration",), {"blur": [1.0]})


def synthetic(methods=("kit", "integration", "hf")):
    sweeps = {}
    for s, lv, clean in (("keep", [0.1, 0.5, 1.0], 1.0), ("C_scale", [0.5, 1.0, 2.0], 1.0)):
        means = {m: {k: [0.3 + 0.1 * i, 0.4, 0.5] for k in rb.METRICS} for i, m in enumerate(methods)}
        means[methods[-1]]["ssim_clahe"] = [None, 0.4, None]    # run at the clean level only: one point
        sweeps[s] = {"label": rb.LABELS[s], "levels": lv, "clean": clean, "means": means}
    return {"methods": list(methods), "sweeps": sweeps}


def test_plot_robustness_draws_a_panel_per_sweep_and_metric_and_a_line_per_method():
    res = synthetic()
    fig = viz.plot_robustness(res)
    axes = fig.get_axes()
    assert len(axes) == 2 * 2                                    # 2 metrics x 2 sweeps
    for ax in axes:
        lines = [ln for ln in ax.get_lines() if ln.get_label() in res["methods"]]
        assert [ln.get_label() for ln in lines] == res["methods"]
        assert ax.get_xlabel() in (rb.LABELS["keep"], rb.LABELS["C_scale"]) and ax.get_ylabel()
        assert min(t.get_fontsize() for t in ax.get_xticklabels() + [ax.xaxis.label, ax.yaxis.label]) >= 9
    hf = [ln for ln in axes[0].get_lines() if ln.get_label() == "hf"][0]
    assert len(hf.get_xdata()) == 1                              # missing levels are left out, not drawn as 0
    assert axes[1].get_xscale() == "log"                         # C_scale: a ratio, on a log axis
    assert len(fig.legends) == 1 and len(fig.legends[0].get_texts()) == 3


def test_plot_robustness_refuses_results_without_sweeps():
    with pytest.raises(ValueError, match="no sweeps"):
        viz.plot_robustness({"methods": ["kit"], "sweeps": {}})


def test_outputs_are_written_and_a_hand_written_interpretation_survives_a_rerun(tiny_results, tmp_path):
    paths = rb.write_outputs(tiny_results, str(tmp_path / "rob_results"))
    assert [p.name for p in paths] == ["rob_results.json", "rob_results.md", "rob_figure.png"]
    md = paths[1]
    note = f"{rb.BEGIN}\nnoise hurts integration most\n{rb.END}"
    md.write_text(md.read_text().replace("# Robustness sweeps\n\n", "# Robustness sweeps\n\n" + note + "\n\n"))
    rb.write_outputs(tiny_results, str(tmp_path / "rob_results"))
    text = md.read_text()
    assert text.count(note) == 1 and text.index(note) < text.index("### keep")
    assert not list(tmp_path.glob(".*partial*"))                  # written beside, renamed into place
