"""Scenario.from_file / from_dict / default / to_dict / with_joint_state: Python data is
read and validated as a scenario file is, with the file's errors."""

import copy
import json
from pathlib import Path

import pytest

import afford
from conftest import EXAMPLES


def default_dict() -> dict:
    return afford.Scenario.from_file(EXAMPLES / "sort-blue-squares.yaml").to_dict()


def errors_of_file(tmp_path, data: dict, suffix: str) -> afford.BadInput:
    """The error of `data` written as a scenario file (JSON text is YAML too)."""
    path = tmp_path / f"bad{suffix}"
    path.write_text(json.dumps(data))
    with pytest.raises(afford.BadInput) as caught:
        afford.Scenario.from_file(path)
    return caught.value


def error_of_dict(data: dict) -> afford.BadInput:
    with pytest.raises(afford.BadInput) as caught:
        afford.Scenario.from_dict(data)
    return caught.value


def test_a_file_read_back_from_its_dict_is_the_same_scenario():
    scenario = afford.Scenario.from_file(EXAMPLES / "sort-blue-squares.yaml")
    again = afford.Scenario.from_dict(scenario.to_dict(), base_dir=scenario.base_dir)
    assert again == scenario
    # Relative robot paths would start elsewhere: another scenario.
    assert afford.Scenario.from_dict(scenario.to_dict()) != scenario
    assert scenario.instruction.lower().startswith("put")
    assert scenario.robot == "kuka_iiwa14"


def test_a_file_without_a_name_is_named_after_its_stem(tmp_path):
    data = default_dict()
    data.pop("name", None)
    path = tmp_path / "my-table.json"
    path.write_text(json.dumps(data))
    assert afford.Scenario.from_file(path).name == "my-table"
    assert afford.Scenario.from_dict(data).name is None


def test_the_default_scenario_is_the_sort_example():
    default = afford.Scenario.default()
    assert default.to_dict() == default_dict()
    assert default.base_dir == Path(".")
    assert afford.Scenario.from_file(EXAMPLES / "sort-blue-squares.yaml").base_dir == EXAMPLES


def test_a_bad_field_in_a_dict_gives_the_files_field_and_message(tmp_path):
    data = default_dict()
    data["objects"][1]["height"] = -0.03
    from_dict = error_of_dict(data)
    assert from_dict.field == "objects[1].height"
    for suffix in (".yaml", ".json"):
        from_file = errors_of_file(tmp_path, data, suffix)
        assert (from_dict.field, from_dict.message) == (from_file.field, from_file.message)
        assert from_dict.issues == from_file.issues
    assert from_dict.file == "<dict>"


def test_a_value_of_the_wrong_type_gives_the_json_files_message(tmp_path):
    data = default_dict()
    data["camera"]["width"] = "wide"
    from_dict = error_of_dict(data)
    from_file = errors_of_file(tmp_path, data, ".json")
    assert from_dict.field == from_file.field == "camera.width"
    assert from_dict.message == from_file.message
    # The dict's text has no line a user wrote: the message names none.
    assert str(from_file).startswith(from_file.file + ":1:")
    assert str(from_dict) == f"<dict>: camera.width: {from_dict.message}"


def test_an_unknown_field_is_named():
    data = default_dict()
    data["objects"][0]["colour"] = "blue"
    e = error_of_dict(data)
    assert e.field.startswith("objects[0]")
    assert "colour" in e.message


def test_python_values_that_are_not_scenario_data_are_refused_by_path():
    data = default_dict()
    data["objects"][0]["box"] = {1, 2, 3}
    e = error_of_dict(data)
    assert e.field == "objects[0].box"
    assert "set" in e.message
    data["objects"][0]["box"] = [float("nan"), 1, 2, 3]
    assert error_of_dict(data).field == "objects[0].box[0]"


def test_tuples_and_numpy_values_read_as_lists_and_numbers():
    np = pytest.importorskip("numpy")
    data = default_dict()
    data["objects"][0]["box"] = tuple(data["objects"][0]["box"])
    data["goals"][0]["box"] = np.array(data["goals"][0]["box"])
    data["objects"][1]["height"] = np.float64(data["objects"][1]["height"])
    assert afford.Scenario.from_dict(data).to_dict() == default_dict()


def test_a_missing_file_is_bad_input_naming_it(tmp_path):
    missing = tmp_path / "nowhere.yaml"
    with pytest.raises(afford.BadInput) as caught:
        afford.Scenario.from_file(missing)
    assert caught.value.file == str(missing)
    assert str(missing) in str(caught.value)


def test_a_joint_state_sets_the_robots_joints():
    scenario = afford.Scenario.from_file(EXAMPLES / "sort-blue-squares.yaml")
    start = afford.plan(scenario, until="joints").start_state
    state = {"name": start["joint_names"], "position": [p + 0.01 for p in start["positions"]]}
    moved = scenario.with_joint_state(state)
    robot = moved.to_dict()["robot"]
    assert "start" not in robot
    assert robot["joints"] == dict(zip(state["name"], state["position"]))
    planned = afford.plan(moved, until="joints").start_state
    assert planned["positions"] == pytest.approx(state["position"])


def test_a_joint_state_message_with_attributes_is_read_too():
    class JointState:  # the shape of a sensor_msgs/msg/JointState
        name = ["a", "b"]
        position = [0.0, 1.0]
        velocity = []

    scenario = afford.Scenario.default()
    with pytest.raises(afford.BadInput) as caught:
        afford.plan(scenario.with_joint_state(JointState()))
    assert "robot" in str(caught.value)


@pytest.mark.parametrize(
    "state, field",
    [
        ({"name": ["a", "a"], "position": [0.0, 0.0]}, "joint_state.name[1]"),
        ({"name": ["a"], "position": [0.0, 1.0]}, "joint_state.position"),
        ({"name": ["a"], "position": [float("inf")]}, "joint_state.position[0]"),
        ({"position": [0.0]}, "joint_state"),
        ({"name": "a", "position": [0.0]}, "joint_state.name"),
    ],
)
def test_a_bad_joint_state_is_named_by_field(state, field):
    with pytest.raises(afford.BadInput) as caught:
        afford.Scenario.default().with_joint_state(state)
    assert caught.value.field == field


def test_to_dict_is_a_copy():
    scenario = afford.Scenario.default()
    d = scenario.to_dict()
    kept = copy.deepcopy(d)
    d["objects"].clear()
    assert scenario.to_dict() == kept
