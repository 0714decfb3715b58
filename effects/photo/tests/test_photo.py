"""The photo effect (issue 26): weather on an image with its depth.

Koschmieder's law exactly; consistency with the renderer on both backends;
the intrinsics path; bad input naming the argument; the depth readers.
"""

import copy
import math

import numpy as np
import pytest

import airlight
from airlight import photo

BACKENDS = airlight.available_backends()


def _koschmieder_inputs(seed=0, height=24, width=40):
    rng = np.random.default_rng(seed)
    image = rng.uniform(0.0, 2.0, (height, width, 3)).astype(np.float32)
    depth = rng.uniform(0.5, 300.0, (height, width)).astype(np.float32)
    depth[:3] = np.inf  # sky: the ray escapes
    return image, depth


@pytest.mark.parametrize("backend", BACKENDS)
def test_koschmieder_law_exact(backend):
    image, depth = _koschmieder_inputs()
    sigma = np.array([0.02, 0.03, 0.05], np.float32)
    a = np.array([0.8, 0.85, 0.9], np.float32)
    weather = {"medium": {"sigma_t": sigma.tolist(), "albedo": 1.0}, "atmospheric_light": a.tolist()}
    out = photo.apply_weather(image, depth, 50.0, weather, backend=backend)
    t = np.exp(-sigma * depth[:, :, None].astype(np.float64))
    expected = image * t + a * (1.0 - t)
    np.testing.assert_allclose(out.transmittance, t, rtol=2e-6, atol=1e-7)
    np.testing.assert_allclose(out.linear, expected, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(out.inscattered, a * (1.0 - t), rtol=1e-5, atol=1e-6)
    assert np.all(out.linear[:3] == np.float32(a))  # endless fog: the sky is A
    # 8-bit sRGB in: decoded to linear first.
    srgb = airlight.to_srgb8(np.clip(image, 0, 1))
    out8 = photo.apply_weather(srgb, depth, 50.0, weather, backend=backend)
    lin = photo.srgb8_to_linear(srgb)
    np.testing.assert_allclose(out8.linear, lin * t + a * (1.0 - t), rtol=1e-5, atol=1e-6)


def test_depth_along_axis():
    """A z-buffer is the ray's depth times the cosine to the optical axis (the renderer's distance_z)."""
    scene = airlight.preset("foggy_street")
    scene["medium"] = None
    clear = airlight.render(scene, "cpu", width=64, outputs=["radiance", "depth", "distance_z"])
    weather = {"medium": {"visibility": 80.0}, "atmospheric_light": 0.5}
    args = (clear["radiance"], None, scene["camera"], weather)
    by_ray = photo.apply_weather(args[0], clear["depth"], *args[2:], backend="cpu")
    by_z = photo.apply_weather(args[0], clear["distance_z"], *args[2:], depth_kind="z", backend="cpu")
    np.testing.assert_allclose(by_z.linear, by_ray.linear, rtol=1e-5, atol=1e-7)


def _projected(scene, width, height):
    """Pixel (x, row) of each lamp in the scene's pinhole camera."""
    cam = scene["camera"]
    pos, look, up = (np.array(cam[k], float) for k in ("position", "look_at", "up"))
    f = (look - pos) / np.linalg.norm(look - pos)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    tan_half = math.tan(math.radians(cam["fov_y"]) / 2)
    for light in scene["lights"]:
        v = np.array(light["position"], float) - pos
        z = v @ f
        if z <= 0:
            continue
        sx = (v @ r) / z / (tan_half * width / height)
        sy = (v @ u) / z / tan_half
        yield (sx + 1) * width / 2 - 0.5, (1 - sy) * height / 2 - 0.5


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("preset", ["foggy_street", "spotlights_crossing_002"])
def test_consistent_with_the_renderer(backend, preset):
    """A clear-air render weathered here equals the render in fog in its airlight and attenuation."""
    scene = airlight.preset(preset)
    # Explicit: conftest.py turns multiple scattering off in renders that leave it unset.
    scene["quality"] = {"multiple_scattering": True}
    fog = scene["medium"]
    width, height = 160, 90
    clear_scene = copy.deepcopy(scene)
    clear_scene["medium"] = None
    clear = airlight.render(clear_scene, backend, width=width, height=height, outputs=["radiance", "depth"])
    foggy = airlight.render(scene, backend, width=width, height=height,
                            outputs=["lamps", "spots", "transmittance", "surfaces"])
    weather = {"medium": fog, "quality": scene["quality"]}
    out = photo.apply_weather(clear["radiance"], clear["depth"], scene["camera"], weather, scene["lights"],
                              backend=backend)
    # Sub-pixel lamp cores are part of the photo, composited over the fog's light
    # in the render: their pixels (and neighbours) are left out.
    keep = np.ones((height, width), bool)
    for x, row in _projected(scene, width, height):
        keep[max(0, int(row) - 2):int(row) + 3, max(0, int(x) - 2):int(x) + 3] = False
    assert keep.mean() > 0.9
    for name in ("lamps", "spots", "transmittance"):
        got, want = out.outputs[name][keep], foggy[name][keep]
        scale = max(float(want.max()), 1e-30)
        assert want.max() > 0 or name != "transmittance"
        err = np.abs(got - want)
        bad = np.argwhere(keep)[np.argmax((err / scale).max(axis=1))]
        assert np.all(err <= 0.005 * np.abs(want) + 1e-4 * scale), (name, float((err / scale).max()),
                                                                     bad.tolist())
    # The surfaces' own light attenuated: the clear radiance times the transmittance.
    np.testing.assert_allclose(out.outputs["surfaces"], clear["radiance"] * out.transmittance,
                               rtol=1e-5, atol=1e-12)


def test_intrinsics_equal_the_pinhole():
    """A centred, square-pixel intrinsics matrix is the film's pinhole; an off-centre one shifts the rays."""
    scene = airlight.preset("foggy_street")
    width, height = 64, 36
    clear_scene = dict(scene, medium=None)
    clear = airlight.render(clear_scene, "cpu", width=width, height=height, outputs=["radiance", "depth"])
    fy = 0.5 * height / math.tan(math.radians(scene["camera"]["fov_y"]) / 2)
    k = np.array([[fy, 0, (width - 1) / 2], [0, fy, (height - 1) / 2], [0, 0, 1]])
    pose = {key: scene["camera"][key] for key in ("position", "look_at", "up")}
    weather = {"medium": scene["medium"]}
    by_fov = photo.apply_weather(clear["radiance"], clear["depth"], scene["camera"], weather, scene["lights"],
                                 backend="cpu")
    by_k = photo.apply_weather(clear["radiance"], clear["depth"], {"intrinsics": k, **pose}, weather,
                               scene["lights"], backend="cpu")
    np.testing.assert_allclose(by_k.linear, by_fov.linear, rtol=1e-4, atol=1e-6)
    k[0, 2] += 10
    shifted = photo.apply_weather(clear["radiance"], clear["depth"], {"intrinsics": k, **pose}, weather,
                                  scene["lights"], backend="cpu")
    lamps = by_fov.outputs["lamps"]
    assert np.abs(shifted.outputs["lamps"] - lamps).max() > 1e-3 * lamps.max()


def test_bad_input_names_the_argument(tmp_path):
    image = np.zeros((4, 6, 3), np.float32)
    depth = np.ones((4, 6), np.float32)
    with pytest.raises(ValueError, match="^depth: shape"):
        photo.apply_weather(image, np.ones((4, 5)), 60.0)
    for bad in (-1.0, np.nan):
        d = depth.copy()
        d[1, 1] = bad
        with pytest.raises(ValueError, match="^depth: "):
            photo.apply_weather(image, d, 60.0)
    with pytest.raises(ValueError, match="^mask: shape"):
        photo.apply_weather(image, depth, 60.0, mask=np.zeros((2, 2), bool))
    with pytest.raises(ValueError, match="^image: "):
        photo.apply_weather(np.zeros((4, 6)), depth, 60.0)
    with pytest.raises(TypeError, match="^camera: "):
        photo.apply_weather(image, depth, None)
    with pytest.raises(ValueError, match="^camera: "):
        photo.apply_weather(image, depth, {"position": [0, 1, 0]})
    with pytest.raises(ValueError, match="^camera: "):
        photo.apply_weather(image, depth, 0.0)
    with pytest.raises(ValueError, match="^camera: .*skew"):
        photo.apply_weather(image, depth, [[5, 1, 3], [0, 5, 2], [0, 0, 1]])
    with pytest.raises(ValueError, match="^depth_kind: "):
        photo.apply_weather(image, depth, 60.0, depth_kind="disparity")
    with pytest.raises(ValueError, match="^weather: unknown key 'surfaces'"):
        photo.apply_weather(image, depth, 60.0, {"surfaces": []})
    with pytest.raises(ValueError, match="^encoding: unknown depth encoding"):
        photo.read_depth(tmp_path / "d.png", "disparity16")


def test_depth_readers_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    depth = rng.uniform(1, 200, (5, 7)).astype(np.float32)
    depth[0, 0] = np.inf
    photo.save_depth_png16(tmp_path / "d.png", depth)
    back = photo.read_depth(tmp_path / "d.png", "kitti")
    assert np.isinf(back[0, 0])
    np.testing.assert_allclose(back[1:], depth[1:], atol=0.5 / 256)
    np.save(tmp_path / "d.npy", depth)
    np.testing.assert_array_equal(photo.read_depth(tmp_path / "d.npy", "npy", invalid=None), depth)
    airlight.save_exr(tmp_path / "d.exr", {"depth": depth, "radiance": np.zeros((5, 7, 3), np.float32)})
    np.testing.assert_array_equal(photo.read_depth(tmp_path / "d.exr", "exr", invalid=None), depth)


# ---- the command-line form ---------------------------------------------------------------

def test_command_line_equals_apply_weather(tmp_path) -> None:
    import json
    import subprocess
    import sys
    from pathlib import Path

    example = Path(__file__).resolve().parents[3] / "examples" / "photo"
    weather = {"medium": {"visibility": 80.0, "albedo": 0.9}, "atmospheric_light": [0.05, 0.05, 0.06]}
    (tmp_path / "w.json").write_text(json.dumps(weather))
    proc = subprocess.run([str(Path(sys.executable).with_name("airlight-photo")), str(example / "street.png"),
                           str(example / "street_depth.png"), "--depth-encoding", "kitti", "--fov", "60",
                           "--weather", str(tmp_path / "w.json"), "--backend", "cpu",
                           "--out", str(tmp_path / "out.exr")], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    from PIL import Image

    image = np.asarray(Image.open(example / "street.png").convert("RGB"))
    depth = photo.read_depth(example / "street_depth.png", "kitti")
    expected = photo.apply_weather(image, depth, 60.0, weather, backend="cpu")
    written = airlight.load_exr(tmp_path / "out.exr")
    np.testing.assert_array_equal(written["radiance"], expected.linear)
    np.testing.assert_array_equal(written["transmittance"], expected.transmittance)


@pytest.mark.parametrize("args, message", [
    (["--fov", "60", "--out", "x.tif"], "--out: must end in .png or .exr"),
    (["--intrinsics", "1,2,3", "--out", "x.png"], "--intrinsics: expected fx,fy,cx,cy"),
    (["--fov", "60", "--weather", "missing.json", "--out", "x.png"], "--weather: cannot read missing.json"),
])
def test_command_line_bad_input_exits_2_with_one_line(tmp_path, args, message) -> None:
    import subprocess
    import sys
    from pathlib import Path

    example = Path(__file__).resolve().parents[3] / "examples" / "photo"
    proc = subprocess.run([str(Path(sys.executable).with_name("airlight-photo")), str(example / "street.png"),
                           str(example / "street_depth.png"), *args], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    assert proc.returncode == 2
    assert len(proc.stderr.splitlines()) == 1 and message in proc.stderr, proc.stderr
