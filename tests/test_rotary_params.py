"""stewart.RotaryParams: the checks of its fields, its parameter files (kind = "rotary") and
its presets."""

import math

import numpy as np
import pytest

import stewart
from stewart.model.rotary_presets import presets

PRESETS = sorted(presets())


@pytest.mark.parametrize("name", PRESETS)
@pytest.mark.parametrize("ext", ["toml", "json"])
def test_file_round_trip(tmp_path, name, ext):
    params = stewart.RotaryParams.preset(name)
    path = tmp_path / f"rig.{ext}"
    params.save(path)
    assert stewart.RotaryParams.load(path) == params
    assert '"kind": "rotary"' in path.read_text() or 'kind = "rotary"' in path.read_text()


def test_files_of_the_other_family_are_refused(tmp_path):
    rotary, linear = tmp_path / "rotary.toml", tmp_path / "linear.toml"
    stewart.RotaryParams.preset("simrig100").save(rotary)
    stewart.PlatformParams.preset("narayan2017").save(linear)
    with pytest.raises(ValueError, match="RotaryParams.load"):
        stewart.PlatformParams.load(rotary)
    with pytest.raises(ValueError, match='kind = "rotary"'):
        stewart.RotaryParams.load(linear)
    assert "kind" not in linear.read_text()  # a linear file stays as it was


def test_preset_sources():
    """The numbers the preset's docstring derives: 750 W servo at 50:1, 90 %: 107.55 N m and
    2 pi rad/s at the crank; the rotor reflected, 0.3 kg m^2, plus the 1 kg lever's 1/300."""
    rig = stewart.RotaryParams.preset("simrig100")
    assert rig.motor_torque_limit.tolist() == [107.55] * 6
    assert rig.motor_speed_limit[0] == pytest.approx(2.0 * math.pi, rel=1e-15)
    assert rig.crank_inertia == pytest.approx(0.3 + 1.0 / 300.0, rel=1e-15)
    # axes a = h x z: unit, normal to the crank, and a positive angle lifts the tip (a x h = z)
    assert np.allclose(np.cross(rig.motor_axes, rig.crank_zero), [0.0, 0.0, 1.0], atol=1e-15)
    with pytest.raises(ValueError, match="unknown rotary preset"):
        stewart.RotaryParams.preset("narayan2017")


def _fields(**changes):
    values = stewart.RotaryParams.preset("simrig100").to_dict()
    values.update(changes)
    return values


@pytest.mark.parametrize("changes, message", [
    ({"motor_axes": np.tile([0.0, 0.0, 1.1], (6, 1))}, "motor_axes: axis 0 has length 1.1"),
    ({"crank_zero": stewart.RotaryParams.preset("simrig100").motor_axes}, "crank_zero: direction 0 is not normal"),
    ({"crank_branch": [1, 1, 0, 1, 1, 1]}, "crank_branch: each value must be"),
    ({"crank_length": 0.0}, "crank_length: must be a positive"),
    ({"rod_length": -0.5}, "rod_length: must be a positive"),
    ({"crank_inertia": 1e-4, "crank_mass": 1.0, "crank_com_distance": 0.05}, "crank_inertia: .* less than"),
    ({"rod_com_distance": 0.6}, "rod_com_distance: .* beyond"),
    ({"rod_inertia": -1.0}, "rod_inertia: must be >= 0"),
    ({"platform_inertia": [1.0, 1.0, 3.0]}, "platform_inertia: .* triangle"),
    ({"crank_angle_limits": [-4.0, 1.0]}, "crank_angle_limits: need -pi"),
    ({"motor_torque_limit": [1.0, 2.0]}, "motor_torque_limit: expected one value or one per leg"),
    ({"motor_speed_limit": 0.0}, "motor_speed_limit: must be finite and > 0"),
    ({"crank_joint_max_angle": 2.0}, "crank_joint_max_angle: need 0 < angle"),
    ({"crank_pin_max_tilt": 0.0}, "crank_pin_max_tilt: need 0 < angle"),
    ({"crank_pin_max_tilt": "wide"}, "crank_pin_max_tilt"),
    ({"kind": "linear"}, "kind: 'linear' is not a rotary"),
    ({"stroke": 1.0}, "unknown parameter field"),
])
def test_checked_on_construction(changes, message):
    with pytest.raises(ValueError, match=message):
        stewart.RotaryParams.from_dict(_fields(**changes))


def test_immutable():
    rig = stewart.RotaryParams.preset("desktop_servo")
    with pytest.raises(ValueError):
        rig.motor_axes[0, 0] = 1.0
    with pytest.raises(AttributeError):
        rig.crank_length = 1.0
    assert rig.replace(crank_branch=-np.ones(6)).crank_branch.tolist() == [-1.0] * 6

