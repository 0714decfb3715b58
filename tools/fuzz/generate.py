"""Random *valid* scenes over the whole documented parameter space (README "Scene format").

Every draw is either an ordinary value or, with probability ``corner_p``, a corner: a bound
of the documented range (0, 1, the largest and smallest accepted value), a tiny or huge
magnitude, or a special placement (a lamp inside a surface, the camera inside a lamp or a
box, the camera on a plane looking along it). A scene is a plain dict; the harness checks
each one with :func:`airlight.load_scene` and treats a refusal as a bug of this generator.

Regions of the space can be left out by name (:data:`REGIONS`, ``GeneratorConfig.exclude``)
so that a short run can skip a known finding until it is fixed.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from typing import Any, Callable

Scene = dict[str, Any]

# Regions that GeneratorConfig.exclude may name; each is a family of draws the generator can
# leave out (the short in-suite run leaves out those with an open finding).
REGIONS = {
    "huge_intensity": "light intensities and sky/sun radiances above 1e12",
    "huge_coordinates": "scene scales of 1e5 m and more (coordinates up to the 1e7 bound)",
    "tiny_fov": "fields of view below 0.01 degrees",
    "huge_film": "films of 4096 to 16384 pixels on a side",
    "march_max": "quality.march_steps near its bound 65536",
    "many_lights": "scenes of 20 to 120 lights",
    "huge_medium": "medium sigma_t above 10 /m",
    "camera_inside_lamp": "the camera inside a lamp's sphere",
    "daytime": "sky, sun and atmosphere keys",
    "display": "the display object",
    "spot": "spot lights",
    "extreme_phase": "|g| within 1e-3 of 1",
    "empty_key": 'bad inputs: the unknown key "" (an empty string)',
}


@dataclass
class GeneratorConfig:
    """What :func:`random_scene` draws from.

    ``max_width``/``max_height`` bound the film (corners aside); ``fixed_film`` forces one
    size (the short run's 8x6); ``exclude`` names :data:`REGIONS` to leave out.
    """

    max_width: int = 48
    max_height: int = 32
    fixed_film: tuple[int, int] | None = None
    max_lights: int = 8
    max_surfaces: int = 8
    corner_p: float = 0.2
    exclude: frozenset[str] = field(default_factory=frozenset)

    def allows(self, region: str) -> bool:
        """False when ``region`` (a key of :data:`REGIONS`) is excluded."""
        if region not in REGIONS:
            raise KeyError(f"unknown generator region {region!r}; known: {', '.join(sorted(REGIONS))}")
        return region not in self.exclude


class _Draw:
    """The random source of one scene, with helpers for ordinary and corner values."""

    def __init__(self, rng: random.Random, config: GeneratorConfig) -> None:
        self.rng = rng
        self.config = config

    def corner(self) -> bool:
        """True with probability ``corner_p``: draw a corner value this time."""
        return self.rng.random() < self.config.corner_p

    def chance(self, p: float) -> bool:
        """True with probability ``p``."""
        return self.rng.random() < p

    def choice(self, items: list[Any]) -> Any:
        """One of ``items``."""
        return items[self.rng.randrange(len(items))]

    def log_uniform(self, lo: float, hi: float) -> float:
        """A value whose logarithm is uniform in [log lo, log hi] (lo, hi > 0)."""
        return math.exp(self.rng.uniform(math.log(lo), math.log(hi)))

    def value(self, ordinary: Callable[[], float], corners: list[float]) -> float:
        """``ordinary()``, or one of ``corners`` with probability ``corner_p``."""
        return self.choice(corners) if corners and self.corner() else ordinary()

    def rgb(self, ordinary: Callable[[], float], corners: list[float], hi: float | None = None) -> Any:
        """An RGB value: one number or a list of three (sometimes with different corners)."""
        def one() -> float:
            v = self.value(ordinary, corners)
            return min(v, hi) if hi is not None else v

        if self.chance(0.4):
            return one()
        return [one(), one(), one()]

    def unit(self) -> list[float]:
        """A random unit vector (uniform on the sphere)."""
        while True:
            v = [self.rng.gauss(0.0, 1.0) for _ in range(3)]
            n = math.sqrt(sum(x * x for x in v))
            if n > 1e-3:
                return [x / n for x in v]

    def direction(self) -> list[float]:
        """A nonzero direction, not always unit: axis-aligned, random, tiny or huge length."""
        if self.corner():
            axis = self.choice([[0.0, -1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0],
                                [1e-9, -1.0, 0.0], [1e-12, 1e-12, -1e-12], [3e6, 0.0, -4e6]])
            return list(axis)
        scale = self.choice([1.0, 1.0, self.log_uniform(1e-3, 1e3)])
        return [x * scale for x in self.unit()]

    def point(self, centre: list[float], scale: float) -> list[float]:
        """A point around ``centre`` at distance ~``scale``, clamped to the 1e7 coordinate bound."""
        return [_clamp_coord(c + self.rng.gauss(0.0, scale)) for c in centre]


def _clamp_coord(x: float) -> float:
    return max(-9.9e6, min(9.9e6, x))


def _intensity(d: _Draw) -> Any:
    corners = [0.0, 1e-30, 1e-6, 1e6, 1e9]
    if d.config.allows("huge_intensity"):
        corners += [1e15, 1e20, 1e30]
    return d.rgb(lambda: d.log_uniform(1e-2, 1e5), corners)


def _albedo(d: _Draw) -> Any:
    return d.rgb(lambda: d.rng.uniform(0.0, 1.0), [0.0, 1.0, 1e-6, 0.999999])


def _asymmetry(d: _Draw) -> float:
    corners = [0.0, 0.5, -0.5, 0.95, -0.95]
    if d.config.allows("extreme_phase"):
        corners += [0.999, -0.999, 0.9999999, -0.9999999, 1 - 1e-12]
    return d.value(lambda: d.rng.uniform(-0.95, 0.95), corners)


def _phase(d: _Draw) -> dict[str, Any]:
    kind = d.choice(["isotropic", "hg", "rayleigh", "hg2"])
    if kind == "hg":
        return {"type": "hg", "g": _asymmetry(d)}
    if kind == "hg2":
        return {"type": "hg2", "forward_g": _asymmetry(d), "backward_g": _asymmetry(d),
                "forward_weight": d.value(lambda: d.rng.uniform(0, 1), [0.0, 1.0])}
    return {"type": kind}


def _medium(d: _Draw) -> dict[str, Any] | None:
    if d.chance(0.2):
        return None
    corners = [0.0, 1e-9, 1e-4, 2.0]
    if d.config.allows("huge_medium"):
        corners += [50.0, 1e3]  # 1e3: the bound (max_extinction)
    medium: dict[str, Any] = {"sigma_t": d.rgb(lambda: d.log_uniform(1e-4, 0.5), corners)}
    if d.chance(0.7):
        medium["albedo"] = _albedo(d)
    if d.chance(0.7):
        medium["phase"] = _phase(d)
    return medium


def _radius(d: _Draw) -> float:
    return d.value(lambda: d.log_uniform(1e-3, 1.0), [1e-6, 1e-4, 5.0, 1e3])  # 1e-6, 1e3: the bounds


def _core_radiance_radius(intensity: Any, radius: float) -> float:
    """The radius raised, where needed, to keep the core radiance I / (pi r^2) within 1e30 (README)."""
    peak = max(intensity) if isinstance(intensity, list) else float(intensity)
    return max(radius, math.sqrt(peak / (math.pi * 1e30)) * (1 + 1e-6))


def _light(d: _Draw, centre: list[float], scale: float) -> dict[str, Any]:
    light: dict[str, Any] = {"position": d.point(centre, scale), "intensity": _intensity(d)}
    if d.config.allows("spot") and d.chance(0.4):
        light["type"] = "spot"
        light["direction"] = d.direction()
        light["cone_angle"] = d.value(lambda: d.rng.uniform(1.0, 90.0), [1e-3, 0.01, 1.0, 89.999, 90.0])
        if d.chance(0.7):
            light["edge"] = d.value(lambda: d.rng.uniform(0, 1), [0.0, 1.0])
    else:
        light["type"] = "point"
    given = d.chance(0.7)
    radius = _radius(d) if given else 0.05  # 0.05: the default
    raised = _core_radiance_radius(light["intensity"], radius)
    if given or raised != radius:
        light["radius"] = raised
    return light


def _surface(d: _Draw, centre: list[float], scale: float) -> dict[str, Any]:
    kind = d.choice(["plane", "box", "box", "sphere", "sphere"])
    surface: dict[str, Any] = {"type": kind}
    if kind == "plane":
        surface["point"] = d.point(centre, scale)
        surface["normal"] = d.direction()
    elif kind == "box":
        lo = d.point(centre, scale)
        size = [d.value(lambda: d.log_uniform(1e-2, 3.0) * scale, [1e-3, 1e3, 1e-4 * scale])
                for _ in range(3)]
        hi = [_clamp_coord(a + s) for a, s in zip(lo, size)]
        lo = [min(a, b - max(abs(b) * 1e-6, 1e-3)) for a, b in zip(lo, hi)]  # min < max in float32 too
        surface["min"], surface["max"] = lo, hi
    else:
        surface["center"] = d.point(centre, scale)
        surface["radius"] = d.value(lambda: d.log_uniform(1e-2, 2.0) * scale, [1e-5, 1e-3, 1e4, 1e6])
    if d.chance(0.8):
        surface["albedo"] = _albedo(d)
    return surface


def _camera(d: _Draw, centre: list[float], scale: float) -> dict[str, Any]:
    position = d.point(centre, scale)
    while True:
        target = (d.point(centre, scale) if d.chance(0.7)
                  else [_clamp_coord(p + x) for p, x in zip(position, d.direction())])  # within the 1e7 bound
        view = [t - p for t, p in zip(target, position)]
        length = math.sqrt(sum(v * v for v in view))
        if length > 1e-4 * max(1.0, math.sqrt(sum(p * p for p in position))):
            break
    up = [0.0, 1.0, 0.0] if d.chance(0.6) else d.unit()
    # Not parallel to the view (cross product well above the validator's 1e-6).
    unit_view = [v / length for v in view]
    cross = [unit_view[1] * up[2] - unit_view[2] * up[1], unit_view[2] * up[0] - unit_view[0] * up[2],
             unit_view[0] * up[1] - unit_view[1] * up[0]]
    if math.sqrt(sum(c * c for c in cross)) < 1e-2:
        up = [1.0, 0.0, 0.0] if abs(unit_view[0]) < 0.5 else [0.0, 0.0, 1.0]
    corners = [179.9, 179.999, 1.0, 120.0]
    if d.config.allows("tiny_fov"):
        corners += [1e-4, 1e-3]
    fov = d.value(lambda: d.rng.uniform(5.0, 150.0), corners)
    return {"position": position, "look_at": target, "up": up, "fov_y": fov}


def _film(d: _Draw) -> dict[str, int]:
    cfg = d.config
    if cfg.fixed_film is not None:
        return {"width": cfg.fixed_film[0], "height": cfg.fixed_film[1]}
    if d.corner():
        w, h = d.choice([(1, 1), (1, cfg.max_height), (cfg.max_width, 1), (2, 2)])
        if cfg.allows("huge_film") and d.chance(0.15):
            w, h = d.choice([(16384, 1), (1, 16384), (4096, 2)])
        return {"width": w, "height": h}
    return {"width": d.rng.randint(1, cfg.max_width), "height": d.rng.randint(1, cfg.max_height)}


def _quality(d: _Draw) -> dict[str, Any] | None:
    if d.chance(0.5):
        return None
    q: dict[str, Any] = {}
    if d.chance(0.4):
        q["airlight"] = d.choice(["analytic", "march"])
    if d.chance(0.4):
        steps = [1, 2, 7, 64, 1000]
        if d.config.allows("march_max"):
            steps += [65535, 65536]
        q["march_steps"] = d.choice(steps) if d.corner() else d.rng.randint(1, 200)
    if d.chance(0.3):
        q["cull_fraction"] = d.value(lambda: d.rng.uniform(0, 0.01), [0.0, 0.01, 1e-12])
    if d.chance(0.3):
        q["spot_glow_samples"] = 4 * d.rng.randint(1, 16)
    if d.chance(0.3):
        q["sky_segments"] = d.value(lambda: d.rng.randint(2, 64), [2, 64])
    if d.chance(0.3):
        q["rainbow_wavelengths"] = d.choice([3, 5, 9, 17, 33])
    if d.chance(0.3):
        q["multiple_scattering"] = d.chance(0.5)
    if d.chance(0.3):
        corners = [0, 16, 17, 64, 256, 1024, 4096]
        q["sun_shadow_map"] = d.choice(corners) if d.corner() else d.rng.randint(16, 512)
    return q


def _display(d: _Draw) -> dict[str, Any] | None:
    if not d.config.allows("display") or d.chance(0.5):
        return None
    out: dict[str, Any] = {}
    if d.chance(0.6):
        out["exposure"] = "auto" if d.chance(0.4) else d.value(lambda: d.log_uniform(1e-3, 1e3),
                                                                [0.0, 1e-30, 1e30])
    if d.chance(0.6):
        out["tonemap"] = d.choice(["loglog", "reinhard", "filmic", "linear"])
    if d.chance(0.3):
        out["white"] = d.value(lambda: d.log_uniform(0.1, 1e3), [1e-30, 1e30])
    if d.chance(0.4):
        glare: dict[str, Any] = {}
        if d.chance(0.7):
            glare["pupil_diameter"] = ("auto" if d.chance(0.3)
                                       else d.value(lambda: d.rng.uniform(1, 9), [1.0, 9.0]))
        if d.chance(0.5):
            glare["eyelashes"] = d.chance(0.5)
        out["glare"] = glare
    return out


def _daytime(d: _Draw, scene: Scene) -> None:
    needs_sun = False
    if d.chance(0.7):
        radiance = d.rgb(lambda: d.log_uniform(1e-3, 10.0), [0.0, 1e6] +
                         ([1e20] if d.config.allows("huge_intensity") else []))
        if d.chance(0.4):
            scene["sky"] = {"model": "overcast", "zenith_radiance": radiance}
        else:
            cie = d.rng.randint(1, 15)
            scene["sky"] = {"model": "cie", "type": cie, "zenith_radiance": radiance}
            needs_sun = cie not in (1, 3, 5)
    if needs_sun or d.chance(0.6):
        sun: dict[str, Any] = {}
        if d.chance(0.8):
            sun["elevation"] = d.value(lambda: d.rng.uniform(-10.0, 90.0),
                                       [-90.0, 90.0, 0.0, 1e-6, -1e-6, 89.9999])
            sun["azimuth"] = d.value(lambda: d.rng.uniform(-180.0, 360.0), [0.0, 1e6, -720.0])
        else:
            sun["direction"] = d.direction()
        if d.chance(0.8):
            sun["irradiance"] = d.rgb(lambda: d.log_uniform(1e-2, 100.0), [0.0, 1e5])
        scene["sun"] = sun
    if d.chance(0.8):
        atmosphere: dict[str, Any] = {}
        if d.chance(0.6):
            atmosphere["molecules"] = {} if d.chance(0.3) else {
                "density_scale": d.value(lambda: d.log_uniform(0.1, 10.0), [0.0, 1e6, 1e-6])}
        if d.chance(0.6):
            aerosol: dict[str, Any] = {}
            if d.chance(0.6):
                aerosol["visibility"] = d.value(lambda: d.log_uniform(50.0, 1e5), [3.912e-3, 1.0, 1e9])
            else:
                aerosol["coefficient"] = d.value(lambda: d.log_uniform(1e-6, 0.1), [0.0, 1e3, 10.0])
            if d.chance(0.5):
                aerosol["scale_height"] = d.value(lambda: d.log_uniform(50.0, 1e4), [1e-3, 1.0, 1e5])
            if d.chance(0.4):
                aerosol["g"] = _asymmetry(d)
            if d.chance(0.4):
                aerosol["albedo"] = d.value(lambda: d.rng.uniform(0, 1), [0.0, 1.0])
            atmosphere["aerosol"] = aerosol
        if d.chance(0.6):
            rain: dict[str, Any] = {"rate": d.value(lambda: d.log_uniform(0.1, 100.0), [0.0, 1000.0, 1e-6])}
            if d.chance(0.4):
                rain["density_scale"] = d.value(lambda: d.log_uniform(0.01, 10.0), [0.0, 1e6])
            if d.chance(0.4):
                rain["top"] = d.value(lambda: d.log_uniform(100.0, 1e4), [1e-3, 1e5])
            if d.chance(0.3):
                rain["g"] = _asymmetry(d)
            if d.chance(0.5):
                rain["phase"] = d.choice(["mie", "hg"])
            atmosphere["rain"] = rain
        if d.chance(0.1):
            atmosphere[d.choice(["molecules", "aerosol", "rain"])] = None
        scene["atmosphere"] = atmosphere


def _special_placements(d: _Draw, scene: Scene) -> None:
    """Corners of placement: lamps inside or on surfaces, the camera inside a lamp, a box or
    a sphere, the camera on a plane looking along it (grazing)."""
    cam = scene["camera"]
    lights, surfaces = scene.get("lights", []), scene.get("surfaces", [])
    if lights and surfaces and d.chance(0.2):  # a lamp inside (or on) a surface
        light, surface = d.choice(lights), d.choice(surfaces)
        if surface["type"] == "sphere":
            light["position"] = list(surface["center"])
        elif surface["type"] == "box":
            light["position"] = [(a + b) / 2 for a, b in zip(surface["min"], surface["max"])]
        else:
            light["position"] = list(surface["point"])
    if lights and d.config.allows("camera_inside_lamp") and d.chance(0.1):
        light = d.choice(lights)
        light["position"] = [p + 1e-3 * x for p, x in zip(cam["position"], d.unit())]
        light["radius"] = _core_radiance_radius(light["intensity"], d.choice([0.01, 1.0, 1e3]))
    if surfaces and d.chance(0.1):  # the camera inside a box or a sphere
        surface = d.choice(surfaces)
        if surface["type"] == "sphere":
            cam["position"] = list(surface["center"])
        elif surface["type"] == "box":
            cam["position"] = [(a + b) / 2 for a, b in zip(surface["min"], surface["max"])]
        _fix_look_at(d, cam)
    if d.chance(0.1):  # grazing: the camera on a plane, looking along it
        normal = d.unit()
        surfaces.append({"type": "plane", "point": list(cam["position"]), "normal": list(normal)})
        tangent = _perpendicular(normal)
        reach = _reach(cam["position"])
        cam["look_at"] = [_clamp_coord(p + reach * t) for p, t in zip(cam["position"], tangent)]
        cam["up"] = list(normal)  # a copy: no two places of a scene share a list
        scene["surfaces"] = surfaces


def _reach(position: list[float]) -> float:
    """How far to put look_at: far enough to stay distinct from the position in float32."""
    return max(10.0, 1e-3 * math.sqrt(sum(p * p for p in position)))


def _perpendicular(n: list[float]) -> list[float]:
    a = [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0]
    c = [n[1] * a[2] - n[2] * a[1], n[2] * a[0] - n[0] * a[2], n[0] * a[1] - n[1] * a[0]]
    length = math.sqrt(sum(x * x for x in c))
    return [x / length for x in c]


def _fix_look_at(d: _Draw, cam: dict[str, Any]) -> None:
    view = d.unit()
    cam["look_at"] = [_clamp_coord(p + _reach(cam["position"]) * v) for p, v in zip(cam["position"], view)]
    if abs(view[1]) > 0.99:
        cam["up"] = [1.0, 0.0, 0.0]
    else:
        cam["up"] = [0.0, 1.0, 0.0]


def random_scene(rng: random.Random, config: GeneratorConfig | None = None) -> Scene:
    """One random valid scene drawn with ``rng`` (see the module docstring)."""
    cfg = config or GeneratorConfig()
    d = _Draw(rng, cfg)
    scales = [1e-3, 1e-2, 1e3, 1e4]
    if cfg.allows("huge_coordinates"):
        scales += [1e5, 1e6, 5e6]
    scale = d.value(lambda: d.log_uniform(0.5, 200.0), scales)
    centre = [0.0, 0.0, 0.0] if d.chance(0.7) else d.point([0.0, 0.0, 0.0], scale * 10)
    scene: Scene = {"film": _film(d), "camera": _camera(d, centre, scale)}
    medium = _medium(d)
    if medium is not None or d.chance(0.3):
        scene["medium"] = medium
    n_lights = d.rng.randint(0, cfg.max_lights)
    if cfg.allows("many_lights") and d.chance(0.05):
        n_lights = d.rng.randint(20, 120)
    if n_lights or d.chance(0.5):
        scene["lights"] = [_light(d, centre, scale) for _ in range(n_lights)]
    n_surfaces = d.rng.randint(0, cfg.max_surfaces)
    if n_surfaces or d.chance(0.5):
        scene["surfaces"] = [_surface(d, centre, scale) for _ in range(n_surfaces)]
    if d.chance(0.3):
        scene["background"] = d.rgb(lambda: d.log_uniform(1e-3, 10.0), [0.0, 1e6])
    quality = _quality(d)
    if quality is not None:
        scene["quality"] = quality
    if cfg.allows("daytime") and d.chance(0.35):
        _daytime(d, scene)
    display = _display(d)
    if display is not None:
        scene["display"] = display
    _special_placements(d, scene)
    return scene


def scene_rng(seed: int, index: int) -> random.Random:
    """The random source of scene ``index`` of the run with ``seed`` (independent of the others)."""
    return random.Random(f"airlight-fuzz:{seed}:{index}")
