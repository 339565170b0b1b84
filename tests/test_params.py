"""PlatformParams: validation, presets and parameter files."""

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import stewart
from stewart import PlatformParams


def _valid_kwargs():
    return PlatformParams.preset("narayan2017").to_dict()


def test_presets_listed_and_built():
    names = stewart.presets()
    assert {"narayan2017", "motion_simulator"} <= set(names)
    for name in names:
        params = PlatformParams.preset(name)
        assert params.name == name
        assert params.is_axisymmetric


def test_narayan2017_geometry_is_the_paper_converted_to_z_up():
    params = PlatformParams.preset("narayan2017")
    # Seed paper, section VIII, point 5 (y-up): base (-0.019, 0, 0.1001), top (-0.0507, 0, 0.046).
    np.testing.assert_array_equal(params.base_points[4], [-0.019, -0.1001, 0.0])
    np.testing.assert_array_equal(params.platform_points[4], [-0.0507, -0.046, 0.0])
    assert params.platform_mass == 6.77406


def test_narayan2017_leg_masses_from_stated_dimensions():
    params = PlatformParams.preset("narayan2017")
    # Hand calculation, steel 7850 kg/m^3: tube 50/40 mm x 100 mm; rod 40 mm x 90 mm.
    cyl = 7850 * math.pi * (0.025**2 - 0.020**2) * 0.100
    rod = 7850 * math.pi * 0.020**2 * 0.090
    # reached 0: a bound of a few ulp
    assert params.cylinder_mass == pytest.approx(cyl, rel=1e-15)
    assert params.piston_mass == pytest.approx(rod, rel=1e-15)
    assert params.piston_inertia[0] == pytest.approx(0.5 * rod * 0.020**2, rel=1e-15)
    assert params.piston_inertia[1] == pytest.approx(rod * (3 * 0.020**2 + 0.090**2) / 12, rel=1e-15)


def test_arrays_are_read_only_and_params_immutable():
    params = PlatformParams.preset("narayan2017")
    with pytest.raises(ValueError):
        params.base_points[0, 0] = 1.0
    with pytest.raises(AttributeError):
        params.platform_mass = 1.0


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("base_points", np.zeros((5, 3)), "base_points: expected shape (6, 3)"),
        ("platform_points", [[0.0, 0.0, np.nan]] * 6, "platform_points: coordinates must be finite"),
        ("base_points", [[i, 0.0, 0.0] for i in range(6)], "base_points: the six points are collinear"),
        ("platform_points", [[0.1, 0, 0]] * 2 + [[0, 0.1, 0], [0, 0.2, 0], [0.3, 0, 0], [0, 0, 0]], "points 0 and 1 coincide"),
        ("platform_mass", -1.0, "platform_mass: must be >= 0"),
        ("cylinder_mass", float("inf"), "cylinder_mass: must be finite"),
        ("piston_mass", "heavy", "piston_mass: expected a number"),
        ("platform_inertia", (1.0, 1.0, 3.0), "platform_inertia: principal moments"),
        ("cylinder_inertia", (-1e-3, 1e-3, 1e-3), "cylinder_inertia: principal moments must be >= 0"),
        ("piston_inertia", (1.0, 2.0), "piston_inertia: expected 3 values"),
        ("cylinder_com_distance", -0.1, "cylinder_com_distance: must be >= 0"),
        ("gravity", float("nan"), "gravity: must be finite"),
        ("leg_length_limits", (0.3, 0.2), "leg_length_limits: need finite 0 < min < max"),
        ("universal_joint_max_angle", 30.0, "universal_joint_max_angle: need 0 < angle <= 1.5708"),
        ("spherical_joint_max_angle", 0.0, "spherical_joint_max_angle: need 0 < angle"),
        ("spherical_joint_max_angle", "wide", "spherical_joint_max_angle: expected a number"),
        ("leg_diameter", -0.05, "leg_diameter: need > 0 (metres), got -0.05"),
        ("leg_diameter", float("inf"), "leg_diameter: must be finite"),
        ("name", 42, "name: expected a string"),
        ("universal_joint_axes", [[1.0, 0.0, 0.0]] * 5 + [[0.0, 0.0, 0.0]], "universal_joint_axes: axis 5 is zero"),
        ("universal_joint_axes", [[1.0, 0.0, 0.0]] * 5 + [[0.6, 0.6, 0.0]], "universal_joint_axes: axis 5 has length"),
        ("universal_joint_axes", [[1.0, 0.0, np.inf]] * 6, "universal_joint_axes: values must be finite"),
        ("universal_joint_axes", [[1.0, 0.0, 0.0]] * 3, "universal_joint_axes: expected shape (6, 3)"),
        ("platform_com", (0.0, np.nan, 0.0), "platform_com: values must be finite"),
        ("platform_inertia", [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], "platform_inertia: the inertia tensor must be symmetric"),
        ("platform_inertia", [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.5]], "platform_inertia: the inertia tensor must be positive-semidefinite"),
        ("platform_inertia", [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.5]], "platform_inertia: principal moments"),
        ("platform_inertia", np.eye(2), "platform_inertia: expected 3 principal moments or a (3, 3) tensor"),
    ],
)
def test_bad_parameters_name_the_field(field, value, message):
    kwargs = _valid_kwargs()
    kwargs[field] = value
    with pytest.raises(ValueError, match=None) as info:
        PlatformParams(**kwargs)
    assert message in str(info.value)


def test_massless_legs_are_allowed():
    kwargs = _valid_kwargs()
    kwargs.update(cylinder_mass=0.0, piston_mass=0.0, cylinder_inertia=(0, 0, 0), piston_inertia=(0, 0, 0))
    assert PlatformParams(**kwargs).cylinder_mass == 0.0


def test_non_axisymmetric_legs_warn():
    kwargs = _valid_kwargs()
    kwargs["cylinder_inertia"] = (1e-4, 6e-4, 5e-4)
    with pytest.warns(stewart.NonAxisymmetricLegWarning, match="I_yy != I_zz"):
        params = PlatformParams(**kwargs)
    assert not params.is_axisymmetric


def test_non_axisymmetric_legs_with_joint_axes_do_not_warn():
    kwargs = _valid_kwargs()
    kwargs["cylinder_inertia"] = (1e-4, 6e-4, 5e-4)
    axes = PlatformParams.preset("narayan2017").with_universal_joints().universal_joint_axes
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        params = PlatformParams(**kwargs, universal_joint_axes=axes)
    assert not params.is_axisymmetric and not params.is_paper_model


def test_joint_axis_parallel_to_its_leg_at_home_names_the_field():
    params = PlatformParams.preset("narayan2017")
    home = stewart.model.kinematics.home_pose(params)
    axes = np.array(params.with_universal_joints().universal_joint_axes)
    axes[2] = stewart.model.kinematics.leg_unit_vectors(params, home)[2]
    with pytest.raises(ValueError, match="^universal_joint_axes: axis 2 is parallel to leg 2 at the home pose"):
        stewart.Platform(params.with_universal_joints(axes))
    stewart.model.kinematics.check_universal_joint_axes(params.with_universal_joints())


def test_default_joint_axes_are_horizontal_and_tangential(preset_params):
    general = preset_params.with_universal_joints()
    axes = general.universal_joint_axes
    radial = preset_params.base_points - preset_params.base_points.mean(axis=0)
    np.testing.assert_allclose(np.linalg.norm(axes, axis=1), 1.0, rtol=0, atol=1e-15)
    np.testing.assert_allclose(axes[:, 2], 0.0, atol=0)
    np.testing.assert_allclose(np.sum(axes * radial, axis=1), 0.0, atol=5e-16)  # reached 1/72 of it
    assert not axes.flags.writeable and preset_params.is_paper_model and not general.is_paper_model
    assert general.replace(universal_joint_axes=None) == preset_params


def test_inertia_tensor_and_paper_model():
    params = PlatformParams.preset("narayan2017")
    moments = params.platform_inertia
    np.testing.assert_array_equal(params.platform_inertia_tensor, np.diag(moments))
    as_tensor = params.replace(platform_inertia=np.diag(moments), platform_com=(0.0, 0.0, 0.0))
    assert as_tensor.is_paper_model and as_tensor.platform_inertia.shape == (3, 3)
    assert not as_tensor.platform_inertia.flags.writeable and not as_tensor.platform_com.flags.writeable
    tilted = np.diag(moments)
    tilted[0, 1] = tilted[1, 0] = 0.01 * moments[0]
    assert not params.replace(platform_inertia=tilted).is_paper_model
    assert not params.replace(platform_com=(0.0, 0.0, 1e-3)).is_paper_model


def test_with_payload_by_the_parallel_axis_theorem():
    """Hand-worked: a 2 kg platform, I = diag(1, 1, 2), at the origin; a 2 kg point-like box
    with I = diag(0.1, 0.2, 0.3) at (0.4, 0, 0.2). Centre of mass (0.2, 0, 0.1); each body
    is 0.2236 m from it along (±0.2, 0, ±0.1), adding m(|d|^2 E - d d^T) = 2 [[0.01, 0, -0.02],
    [0, 0.05, 0], [-0.02, 0, 0.04]] each."""
    kwargs = _valid_kwargs()
    kwargs.update(platform_mass=2.0, platform_inertia=(1.0, 1.0, 2.0))
    params = PlatformParams(**kwargs)
    loaded = params.with_payload(2.0, (0.4, 0.0, 0.2), (0.1, 0.2, 0.3))
    assert loaded.platform_mass == 4.0
    np.testing.assert_allclose(loaded.platform_com, (0.2, 0.0, 0.1), rtol=0, atol=1e-16)
    expected = np.array([[1.1 + 0.04, 0.0, -0.08], [0.0, 1.2 + 0.2, 0.0], [-0.08, 0.0, 2.3 + 0.16]])
    np.testing.assert_allclose(loaded.platform_inertia_tensor, expected, rtol=0, atol=1e-15)
    # Two payloads in turn equal their combination, and a payload at the origin keeps the paper's model.
    again = loaded.with_payload(1.0, (0.0, 0.5, 0.0), np.eye(3) * 0.05)
    both = params.with_payload(3.0, (0.8 / 3.0, 0.5 / 3.0, 0.4 / 3.0),
                               PlatformParams(**{**kwargs, "platform_mass": 2.0, "platform_inertia": (0.1, 0.2, 0.3),
                                                 "platform_com": (0.4, 0.0, 0.2)})
                               .with_payload(1.0, (0.0, 0.5, 0.0), np.eye(3) * 0.05).platform_inertia_tensor)
    np.testing.assert_allclose(again.platform_inertia_tensor, both.platform_inertia_tensor, rtol=1e-14, atol=0)
    centred = params.with_payload(1.0, (0.0, 0.0, 0.0), (0.1, 0.1, 0.2))
    assert centred.is_paper_model and centred.platform_inertia.shape == (3,)
    np.testing.assert_array_equal(centred.platform_inertia, (1.1, 1.1, 2.2))
    with pytest.raises(ValueError, match="^com: expected 3 values"):
        params.with_payload(1.0, (0.0, 0.0), (0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match="^inertia: principal moments"):
        params.with_payload(1.0, (0.0, 0.0, 0.0), (0.1, 0.1, 0.3))
    with pytest.raises(ValueError, match="^mass: must be >= 0"):
        stewart.Platform.preset("narayan2017").with_payload(-1.0, (0.0, 0.0, 0.0), (0.1, 0.1, 0.1))


def test_general_fields_round_trip_through_files(tmp_path):
    params = (PlatformParams.preset("narayan2017").with_universal_joints()
              .with_payload(3.0, (0.01, -0.02, 0.05), [[0.1, 0.01, 0.0], [0.01, 0.12, 0.0], [0.0, 0.0, 0.2]]))
    assert params.platform_inertia.shape == (3, 3)
    for suffix in (".toml", ".json"):
        params.save(tmp_path / f"p{suffix}")
        loaded = PlatformParams.load(tmp_path / f"p{suffix}")
        assert loaded == params and hash(loaded) == hash(params)
        np.testing.assert_array_equal(loaded.universal_joint_axes, params.universal_joint_axes)
        np.testing.assert_array_equal(loaded.platform_inertia, params.platform_inertia)
        np.testing.assert_array_equal(loaded.platform_com, params.platform_com)
    assert params != params.replace(platform_com=None)


def test_unknown_preset_lists_the_available_ones():
    with pytest.raises(ValueError, match="unknown preset 'nope'; available: .*narayan2017"):
        PlatformParams.preset("nope")


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_file_round_trip_is_exact(tmp_path, preset_params, suffix):
    path = tmp_path / f"platform{suffix}"
    preset_params.save(path)
    loaded = PlatformParams.load(path)
    assert loaded == preset_params
    np.testing.assert_array_equal(loaded.base_points, preset_params.base_points)
    assert loaded.leg_length_limits == preset_params.leg_length_limits


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_workspace_bounds_round_trip_through_files(tmp_path, suffix):
    bounds = dict(universal_joint_max_angle=0.5, spherical_joint_max_angle=0.7, leg_diameter=0.03)
    params = PlatformParams.preset("narayan2017").replace(**bounds)
    path = tmp_path / f"platform{suffix}"
    params.save(path)
    loaded = PlatformParams.load(path)
    assert {key: getattr(loaded, key) for key in bounds} == bounds
    assert PlatformParams.from_dict(params.to_dict()) == params != PlatformParams.preset("narayan2017")


def test_toml_file_is_readable_by_hand(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(
        """
name = "hand"
base_points = [[1, 0, 0], [0.5, 0.8, 0], [-0.5, 0.8, 0], [-1, 0, 0], [-0.5, -0.8, 0], [0.5, -0.8, 0]]
platform_points = [[0.5, 0.1, 0], [0.2, 0.5, 0], [-0.2, 0.5, 0], [-0.5, 0.1, 0], [-0.2, -0.5, 0], [0.2, -0.5, 0]]
platform_mass = 100
platform_inertia = [10, 10, 18]
cylinder_mass = 2
cylinder_inertia = [0.01, 0.2, 0.2]
cylinder_com_distance = 0.3
piston_mass = 1
piston_inertia = [0.005, 0.1, 0.1]
piston_com_distance = 0.3
"""
    )
    params = PlatformParams.load(path)
    assert params.gravity == 9.81 and params.leg_length_limits is None and params.leg_diameter is None
    assert params.platform_inertia.tolist() == [10.0, 10.0, 18.0]


def test_bad_files_name_the_problem(tmp_path):
    path = tmp_path / "p.json"
    data = _valid_kwargs()
    data["platform_mas"] = data.pop("platform_mass")
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="unknown parameter field\\(s\\): platform_mas"):
        PlatformParams.load(path)
    path.write_text("{not json")
    with pytest.raises(ValueError, match="not a valid JSON file"):
        PlatformParams.load(path)
    with pytest.raises(ValueError, match="cannot tell the format"):
        PlatformParams.load(tmp_path / "p.yaml")


def test_equality_and_hash_follow_values():
    a = PlatformParams.preset("narayan2017")
    b = PlatformParams.preset("narayan2017")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c = a.replace(platform_mass=7.0)
    assert a == b and hash(a) == hash(b)
    assert a != c


_positive = st.floats(min_value=1e-300, max_value=1e300, allow_nan=False, allow_infinity=False)


@settings(max_examples=60, deadline=None)
@given(
    scale=st.floats(min_value=1e-6, max_value=1e6),
    mass=_positive,
    moment=_positive,
    ratio=st.floats(min_value=0.0, max_value=2.0),
    fmt=st.sampled_from(["toml", "json"]),
)
def test_any_valid_parameters_round_trip_through_files(tmp_path_factory, scale, mass, moment, ratio, fmt):
    """Every float that validation accepts is written and read back bit for bit."""
    base = PlatformParams.preset("narayan2017")
    params = base.replace(
        base_points=base.base_points * scale,
        platform_points=base.platform_points * scale,
        platform_mass=mass,
        platform_inertia=(moment, moment, moment * ratio),
        cylinder_com_distance=scale / 3,
    )
    path = tmp_path_factory.mktemp("files") / f"p.{fmt}"
    params.save(path)
    loaded = PlatformParams.load(path)
    assert loaded == params
    np.testing.assert_array_equal(loaded.platform_points, params.platform_points)


def test_params_module_imports_point_one_way():
    """params builds its parameter sets from presets' fields and reads and writes them with
    paramfile; neither imports params back, and no function imports a module lazily."""
    import ast
    import importlib.util

    def imports(module):
        tree = ast.parse(open(importlib.util.find_spec(module).origin, encoding="utf-8").read())
        found = []
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                found += [(node.module or "") + "." + alias.name for alias in node.names]
                found += [node.module or ""]
            elif isinstance(node, ast.Import):
                found += [alias.name for alias in node.names]
        lazy = [n for f in ast.walk(tree) if isinstance(f, ast.FunctionDef)
                for n in ast.walk(f) if isinstance(n, (ast.Import, ast.ImportFrom))]
        return found, lazy

    params_imports, params_lazy = imports("stewart.model.params")
    assert "presets" in params_imports and ".paramfile" in params_imports and not params_lazy
    for module in ("stewart.model.presets", "stewart.model.paramfile"):
        found, _ = imports(module)
        assert not any("params" in name and "paramfile" not in name for name in found), (module, found)
