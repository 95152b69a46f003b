"""LPIPS without torchvision: the network, loading weight files, the unavailable case, fetching."""
import hashlib
import http.server
import threading
from functools import partial

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from evinr_lite.evaluation.lpips import (ALEXNET_FILE, FETCH_COMMAND, LINEAR_FILE, LPIPS, LPIPSUnavailable, load_lpips, lpips_distance, lpips_distances, lpips_paths)

# torchvision's AlexNet `features` (IMAGENET1K_V1) and LPIPS v0.1 heads: the published shapes
ALEX_SHAPES = {
    "features.0.weight": (64, 3, 11, 11), "features.0.bias": (64,),
    "features.3.weight": (192, 64, 5, 5), "features.3.bias": (192,),
    "features.6.weight": (384, 192, 3, 3), "features.6.bias": (384,),
    "features.8.weight": (256, 384, 3, 3), "features.8.bias": (256,),
    "features.10.weight": (256, 256, 3, 3), "features.10.bias": (256,),
}
LIN_SHAPES = {f"lin{k}.model.1.weight": (1, c, 1, 1) for k, c in enumerate((64, 192, 384, 256, 256))}


def generated_state_dicts(seed=0):
    g = torch.Generator().manual_seed(seed)
    alex = {k: torch.randn(s, generator=g) * (0.1 if k.endswith("weight") else 0.05) for k, s in ALEX_SHAPES.items()}
    alex["classifier.1.weight"] = torch.randn(4, 8, generator=g)     # stands in for the classifier (ignored)
    lin = {k: torch.rand(s, generator=g) for k, s in LIN_SHAPES.items()}
    return alex, lin


@pytest.fixture
def weights_dir(tmp_path):
    alex, lin = generated_state_dicts()
    torch.save(alex, tmp_path / ALEXNET_FILE)
    torch.save(lin, tmp_path / LINEAR_FILE)
    return tmp_path


def reference_lpips(x0, x1, alex, lin):
    """LPIPS(alex, v0.1) written out with torch.nn.functional, for one pair of RGB images in [-1, 1]."""
    shift = torch.tensor([-0.030, -0.088, -0.188]).view(1, 3, 1, 1)
    scale = torch.tensor([0.458, 0.448, 0.450]).view(1, 3, 1, 1)

    def feats(x):
        h = (x - shift) / scale
        out = []
        h = F.relu(F.conv2d(h, alex["features.0.weight"], alex["features.0.bias"], stride=4, padding=2))
        out.append(h)
        h = F.relu(F.conv2d(F.max_pool2d(h, 3, 2), alex["features.3.weight"], alex["features.3.bias"], padding=2))
        out.append(h)
        h = F.relu(F.conv2d(F.max_pool2d(h, 3, 2), alex["features.6.weight"], alex["features.6.bias"], padding=1))
        out.append(h)
        h = F.relu(F.conv2d(h, alex["features.8.weight"], alex["features.8.bias"], padding=1))
        out.append(h)
        h = F.relu(F.conv2d(h, alex["features.10.weight"], alex["features.10.bias"], padding=1))
        out.append(h)
        return out

    total = 0.0
    for k, (a, b) in enumerate(zip(feats(x0), feats(x1))):
        na = a / (a.norm(dim=1, keepdim=True) + 1e-10)
        nb = b / (b.norm(dim=1, keepdim=True) + 1e-10)
        w = lin[f"lin{k}.model.1.weight"].view(1, -1, 1, 1)
        total += float(((na - nb) ** 2 * w).sum(dim=1).mean())
    return total


def test_network_has_the_published_parameter_names_and_shapes():
    model = LPIPS()
    shapes = {k: tuple(v.shape) for k, v in model.state_dict().items()}
    assert shapes == {**ALEX_SHAPES, **LIN_SHAPES}
    feats = model.layer_features(torch.zeros(2, 3, 64, 96))
    assert [f.shape[1] for f in feats] == [64, 192, 384, 256, 256]
    assert feats[0].shape[-2:] == (15, 23) and feats[1].shape[-2:] == (7, 11) and feats[4].shape[-2:] == (3, 5)


def test_loads_generated_weight_files_and_matches_an_independent_forward(weights_dir):
    alex, lin = generated_state_dicts()
    model = load_lpips(weights_dir, device="cpu")
    for k, v in model.state_dict().items():
        torch.testing.assert_close(v, (alex | lin)[k])
    rng = np.random.default_rng(0)
    a = rng.uniform(0, 1, (40, 56))
    b = np.clip(a + rng.normal(0, 0.2, a.shape), 0, 1)
    grey = lambda img: torch.as_tensor(2 * img - 1, dtype=torch.float32)[None, None].expand(1, 3, -1, -1)
    expected = reference_lpips(grey(a), grey(b), alex, lin)
    assert lpips_distance(b, a, model) == pytest.approx(expected, rel=1e-4)
    assert lpips_distance(a, b, model) == pytest.approx(lpips_distance(b, a, model), rel=1e-5)
    assert expected > 0


def test_identical_images_give_zero_and_batches_agree(weights_dir):
    model = load_lpips(weights_dir, device="cpu")
    rng = np.random.default_rng(1)
    imgs = rng.uniform(0, 1, (3, 36, 36))
    assert lpips_distance(imgs[0], imgs[0], model) == pytest.approx(0.0, abs=1e-7)
    d = lpips_distances(imgs, imgs[::-1], model, batch_size=2)
    assert d.shape == (3,) and d[1] == pytest.approx(0.0, abs=1e-7)
    assert d[0] == pytest.approx(lpips_distance(imgs[0], imgs[2], model), rel=1e-5)
    u8 = np.round(imgs * 255).astype(np.uint8)
    assert lpips_distances(u8, imgs, model)[0] < 1e-3     # uint8 frames are read as / 255
    with pytest.raises(ValueError, match="at least 32"):
        lpips_distance(imgs[0, :20, :20], imgs[0, :20, :20], model)


def test_wrong_weight_shapes_are_named(tmp_path):
    alex, lin = generated_state_dicts()
    lin["lin2.model.1.weight"] = torch.zeros(1, 10, 1, 1)
    torch.save(alex, tmp_path / ALEXNET_FILE)
    torch.save(lin, tmp_path / LINEAR_FILE)
    with pytest.raises(ValueError, match=r"lin2\.model\.1\.weight.*\(1, 10, 1, 1\)"):
        load_lpips(tmp_path, device="cpu")
    del alex["features.6.weight"]
    with pytest.raises(ValueError, match=r"features\.6\.weight.*missing"):
        LPIPS().load_weights(alex, generated_state_dicts()[1])


def test_missing_weights_raise_unavailable_with_the_fetch_command(tmp_path, monkeypatch):
    with pytest.raises(LPIPSUnavailable) as err:
        load_lpips(tmp_path / "empty")
    assert FETCH_COMMAND in str(err.value) and FETCH_COMMAND == "python -m data_fetch get lpips all"
    assert ALEXNET_FILE in str(err.value)
    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    alex, lin = lpips_paths()
    assert alex == tmp_path / "cache" / "weights" / "lpips" / ALEXNET_FILE and lin.name == LINEAR_FILE


def test_published_checksums_are_pinned():
    from data_fetch.registry import WEIGHTS
    files = WEIGHTS["lpips"]
    assert {f.file for f in files.values()} == {ALEXNET_FILE, LINEAR_FILE}
    for f in files.values():
        alg, _, digest = f.known_hash.partition(":")
        assert alg == "sha256" and len(digest) == 64 and int(digest, 16) >= 0
    # torchvision names its file after the first 8 hex digits of the sha256
    assert files["alexnet"].known_hash.split(":")[1].startswith(ALEXNET_FILE.split("-")[-1].split(".")[0])


@pytest.fixture
def file_server(tmp_path):
    root = tmp_path / "www"
    root.mkdir()
    handler = partial(http.server.SimpleHTTPRequestHandler, directory=str(root))
    handler.log_message = lambda *a: None
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=httpd.serve_forever, kwargs={"poll_interval": 0.02}, daemon=True).start()
    yield root, f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()
    httpd.server_close()


def test_data_fetch_gets_the_weights_once_verified(file_server, tmp_path, monkeypatch):
    from dataclasses import replace

    import data_fetch
    from data_fetch import ChecksumError
    from data_fetch.__main__ import main as cli
    from data_fetch.registry import WEIGHTS

    root, url = file_server
    alex, lin = generated_state_dicts()
    torch.save(alex, root / ALEXNET_FILE)
    torch.save(lin, root / LINEAR_FILE)
    sha = {n: hashlib.sha256((root / n).read_bytes()).hexdigest() for n in (ALEXNET_FILE, LINEAR_FILE)}
    served = {k: replace(f, url=f"{url}/{f.file}", known_hash=f"sha256:{sha[f.file]}") for k, f in WEIGHTS["lpips"].items()}
    monkeypatch.setitem(WEIGHTS, "lpips", served)
    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    assert cli(["get", "lpips", "all", "--quiet"]) == 0
    paths = data_fetch.get_all("lpips", progress=False)
    assert {p.name for p in paths.values()} == {ALEXNET_FILE, LINEAR_FILE}
    model = load_lpips(device="cpu")                  # found in the default cache folder
    torch.testing.assert_close(model.state_dict()["lin0.model.1.weight"], lin["lin0.model.1.weight"])
    assert data_fetch.get("lpips", "alexnet", progress=False) == paths["alexnet"]
    # a file that does not match its pinned sha256 is refused and not kept
    bad = {**served, "alex_v0.1": replace(served["alex_v0.1"], known_hash="sha256:" + "0" * 64)}
    monkeypatch.setitem(WEIGHTS, "lpips", bad)
    (tmp_path / "cache" / "weights" / "lpips" / LINEAR_FILE).unlink()
    with pytest.raises(ChecksumError):
        data_fetch.get_weights("lpips", ("alex_v0.1",), progress=False)
    assert not (tmp_path / "cache" / "weights" / "lpips" / LINEAR_FILE).exists()
