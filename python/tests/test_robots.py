"""afford.robots and afford.load_robot: the built-in robots and a user's description,
by the rules of a scenario's `robot.model`."""

import shutil

import pytest

import afford
from conftest import REPO, load_json, run_afford


def test_the_builtin_robots_are_afford_robots_list(afford_bin):
    listed = load_json(run_afford(afford_bin, "robots", "--json").stdout.encode())
    robots = afford.robots()
    assert [r.to_dict() for r in robots] == listed
    iiwa = robots[0]
    assert (iiwa.name, iiwa.dof, iiwa.source) == ("kuka_iiwa14", 7, "built-in")
    assert iiwa.joint_names == iiwa.arms[0]["joints"]
    assert all(j["velocity"] > 0 for j in iiwa.joints)


def test_a_user_description_loads_from_its_folder(tmp_path):
    for suffix in (".yaml", ".urdf"):
        shutil.copy(REPO / "robots" / f"kuka_iiwa14{suffix}", tmp_path / f"kuka_iiwa14{suffix}")
    by_yaml = afford.load_robot("kuka_iiwa14.yaml", base_dir=tmp_path)
    by_urdf = afford.load_robot(str(tmp_path / "kuka_iiwa14.urdf"))
    assert by_yaml.to_dict() == by_urdf.to_dict() == afford.load_robot("kuka_iiwa14").to_dict()
    assert by_yaml.source != "built-in" and str(tmp_path) in by_yaml.source


def test_a_robot_that_cannot_be_loaded_is_bad_input(tmp_path):
    with pytest.raises(afford.BadInput) as caught:
        afford.load_robot("kuka_iiwa15")
    assert caught.value.field == "robot.model"
    assert "kuka_iiwa14" in caught.value.message
    shutil.copy(REPO / "robots" / "kuka_iiwa14.urdf", tmp_path / "alone.urdf")
    with pytest.raises(afford.BadInput) as caught:
        afford.load_robot("alone.urdf", base_dir=tmp_path)
    assert "description" in caught.value.message
