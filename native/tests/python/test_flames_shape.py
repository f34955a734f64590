"""Structural flames, shape and render side ([Structural Flames] §4.4-4.5, §5) through the
bindings: profiles, sampling, lights, energy balance (eq. 5-6) and the flame VDB."""
import math

import numpy as np
import pytest

import _native as native


def straight_flame(x=0.0, length=0.3, radius=0.03, ident=1, n=8, speed=1.5):
    z = np.linspace(0.0, length, n)
    points = np.stack([np.full(n, x), np.zeros(n), z], axis=1)
    return dict(points=points, velocities=np.tile([0.0, 0.0, speed], (n, 1)), ages=z / speed,
                radius=radius, id=ident)


def test_profiles_are_normalized_and_curves_are_checked():
    for name in ("candle", "torch", "campfire"):
        p = native.FlameProfile.library(name)
        assert max(p.radius(s) for s in np.linspace(0, 1, 101)) == pytest.approx(1.0)
        assert p.aspect > 1.0
    with pytest.raises(ValueError, match="profile must be one of"):
        native.FlameProfile.library("volcano")
    with pytest.raises(ValueError, match="at least 2 points"):
        native.FlameProfile.from_curve(np.array([[1.0, 0.0]]))
    with pytest.raises(ValueError, match="must not decrease"):
        native.FlameProfile.from_curve(np.array([[1.0, 1.0], [0.5, 0.0]]))
    curve = native.FlameProfile.from_curve(np.array([[0.0, 0.0], [0.2, 0.5], [0.0, 1.0]]))
    assert curve.aspect == pytest.approx(5.0)
    assert curve.radius(0.5) == pytest.approx(1.0)


def test_shape_energy_lights_and_colors():
    camera = native.FlameCamera(position=(0.0, -2.0, 0.3))
    image = np.zeros((4, 2, 3), np.float32)
    image[..., 0] = 1.0  # a red reference image: every base colour is red
    shaper = native.FlameShaper([native.FlameProfile.library("torch")], images=[image], fixed_count=5000, seed=2)
    out = shaper.shape([straight_flame()], 0.5, camera)
    assert out["positions"].shape == (5000, 3) and out["sampled"] == [5000]
    # red, scaled to luminance 1 (the image gives the colour, eq. 5-6 the brightness)
    assert np.allclose(out["colors"], [1.0 / 0.2126, 0.0, 0.0], rtol=1e-5)
    assert out["power"].sum() == pytest.approx(out["energy"][0], rel=0.01)  # Σ P_i = E
    h = 0.3
    l = math.dist((0.0, 0.0, 0.15), (0.0, -2.0, 0.3))
    expected = out["energy"][0] / (4 * math.pi * (0.25 * h * h + l * l))
    assert out["incandescence"].sum() == pytest.approx(expected, rel=0.01)  # eq. 6 sums to eq. 5
    light = out["lights"][0]
    assert light["radius"] == pytest.approx(h / 3, rel=1e-3)
    assert light["energy"] == pytest.approx(out["energy"][0])
    assert np.allclose(light["color"], [1.0 / 0.2126, 0.0, 0.0], rtol=1e-5)
    # d ∈ (0, I]: eq. 4 faded to 0 over the shell's outer half (no hard edge at I/(1+cutoff²))
    assert np.all((out["density"] > 0.0) & (out["density"] <= 1.0))


def test_camera_count_and_bad_input():
    near = native.FlameCamera(position=(0.0, -2.0, 0.15))
    far = native.FlameCamera(position=(0.0, -4.0, 0.15))
    shaper = native.FlameShaper([native.FlameProfile.library("candle")], max_particles=10**7)
    n_near = shaper.shape([straight_flame()], 0.0, near)["sampled"][0]
    n_far = shaper.shape([straight_flame()], 0.0, far)["sampled"][0]
    assert n_far / n_near == pytest.approx(0.25, rel=0.03)  # projected pixels ∝ 1/l²
    with pytest.raises(ValueError, match="at least 2 spine points"):
        shaper.shape([dict(points=np.zeros((1, 3)), radius=0.1)], 0.0, near)
    with pytest.raises(ValueError, match="radius"):
        shaper.shape([dict(points=np.zeros((3, 3)), radius=0.0)], 0.0, near)
    with pytest.raises(ValueError, match="falloff"):
        native.FlameShaper([native.FlameProfile.library("candle")], falloff=0.0)


def test_write_flames_vdb(tmp_path):
    camera = native.FlameCamera(position=(0.0, -2.0, 0.15))
    shaper = native.FlameShaper([native.FlameProfile.library("candle")], fixed_count=20000, seed=1)
    out = shaper.shape([straight_flame(), straight_flame(x=0.2, ident=2)], 0.25, camera)
    path = tmp_path / "flames_0001.vdb"
    voxels = native.write_flames_vdb(path, out, voxel_size=0.01, light_unit=3.0, opacity=0.5, frame=1)
    assert voxels > 0 and path.exists()
    names = native.vdb_grid_names(str(path))
    assert set(names) == {"emission", "density", "temperature", "flame", "color", "velocity"}
    emission = native.read_vdb_grid(str(path), "emission")
    # The splatted power is conserved: Σ lum(emission) Δx³ = light unit × Σ P_i (mean lum. 1).
    total = (emission["values"].astype(np.float64) @ [0.2126, 0.7152, 0.0722]).sum() * 0.01**3
    assert total == pytest.approx(3.0 * out["power"].astype(np.float64).sum(), rel=1e-3)
    density = native.read_vdb_grid(str(path), "density")  # opacity × Σ d_i m_i / Δx³ (§5.3)
    weight = (out["density"].astype(np.float64) * out["mass"]).sum()
    assert density["values"].astype(np.float64).sum() * 0.01**3 == pytest.approx(0.5 * weight, rel=1e-3)
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="light_unit"):
            native.write_flames_vdb(tmp_path / "bad.vdb", out, voxel_size=0.01, light_unit=bad)
    assert not (tmp_path / "bad.vdb").exists()


def test_obstacles_drop_particles():
    """§6.1 through set_obstacles: no particle left inside the box, the dropped ones counted; the
    same samples otherwise (the box only removes)."""
    camera = native.FlameCamera(position=(0.0, -2.0, 0.15))
    shaper = native.FlameShaper([native.FlameProfile.library("torch")], fixed_count=5000, seed=4)
    free = shaper.shape([straight_flame()], 0.5, camera)
    assert free["obstructed"] == 0
    box = native.BoxSdf((-0.2, -0.2, 0.15), (0.2, 0.2, 0.25))
    shaper.set_obstacles([box])
    out = shaper.shape([straight_flame()], 0.5, camera)
    assert np.all(box.distance(out["positions"]) >= 0.0)
    inside = int((box.distance(free["positions"]) < 0.0).sum())
    assert inside > 500 and out["obstructed"] == inside
    assert len(out["positions"]) == len(free["positions"]) - inside
    shaper.set_obstacles([])
    assert shaper.shape([straight_flame()], 0.5, camera)["obstructed"] == 0
