"""Voxel-list files: round trips, tolerated layouts, every kind of bad line."""

import os

import numpy as np
import pytest

from ladartui.errors import FieldError, InputFileError, OutputFileError
from ladartui.scene.model import Scene
from ladartui.scene.target_model import load_target
from ladartui.scene.voxels import load_voxels, load_voxels_counted, save_voxels, unique_voxels


def write(tmp_path, data: bytes, name="scene.txt"):
    path = tmp_path / name
    path.write_bytes(data)
    return path


def test_round_trip_matches_text_written_independently(tmp_path):
    rng = np.random.default_rng(1)
    voxels = rng.integers(0, 5000, size=(2000, 3)).astype(np.int32)
    voxels, _ = unique_voxels(voxels)
    path = tmp_path / "out.txt"
    save_voxels(path, voxels)
    expected = "".join(f"{x},{y},{z}\n" for x, y, z in voxels.tolist())
    assert path.read_text() == expected
    loaded = load_voxels(path)
    assert loaded.dtype == np.int32 and loaded.shape == (len(voxels), 3)
    np.testing.assert_array_equal(loaded, voxels)


def test_extreme_values_round_trip(tmp_path):
    voxels = np.array([[0, 0, 0], [2**31 - 1, 9, 10], [10, 99, 100]], dtype=np.int64)
    path = tmp_path / "v.txt"
    save_voxels(path, voxels)
    assert path.read_text() == "0,0,0\n2147483647,9,10\n10,99,100\n"
    np.testing.assert_array_equal(load_voxels(path), voxels)


def test_empty_list_round_trip(tmp_path):
    path = tmp_path / "empty.txt"
    save_voxels(path, np.zeros((0, 3), dtype=np.int32))
    assert path.read_bytes() == b""
    assert load_voxels(path).shape == (0, 3)


@pytest.mark.parametrize(
    "data",
    [
        b"1,2,3\n4,5,6\n",
        b"1,2,3\n4,5,6",
        b"1,2,3\r\n4,5,6\r\n",
        b" 1 , 2 ,3\n4,\t5 , 6 \n",
        b"\xef\xbb\xbf1,2,3\n4,5,6\n",
        b"1,2,3\n4,5,6\n\n\n",
        b"1,2,3\r\n4,5,6\r\n  \r\n",
        b"01,002,3\n4,5,6\n",
    ],
)
def test_tolerated_layouts(tmp_path, data):
    np.testing.assert_array_equal(load_voxels(write(tmp_path, data)), [[1, 2, 3], [4, 5, 6]])


@pytest.mark.parametrize(
    "data, line, message",
    [
        (
            b"1,2,3\n4,5\n",
            2,
            "2 comma-separated values in '4,5'; expected three non-negative "
            "integers x,y,z separated by commas",
        ),
        (
            b"1,2,3,4\n",
            1,
            "4 comma-separated values in '1,2,3,4' (a target model's x,y,z,id lines, which "
            "ladartui.scene.target_model.load_target reads with their ids); expected three "
            "non-negative integers x,y,z separated by commas",
        ),
        (
            b"1,2,3,x\n",
            1,
            "4 comma-separated values in '1,2,3,x'; expected three non-negative "
            "integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n4 5 6\n",
            2,
            "1 comma-separated values in '4 5 6'; expected three non-negative "
            "integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n1,2.5,3\n",
            2,
            "y = '2.5' is not a whole number; expected three non-negative integers x,y,z separated by commas",
        ),
        (b"1,2,3\n7,8,-1\n", 2, "z = -1 is negative; voxel indices start at 0"),
        (
            b"1,2,3\n\n4,5,6\n",
            2,
            "blank line before more voxels; blank lines are allowed only at the end of the file",
        ),
        (
            b"1,2,3\n  \r\n4,5,6\n",
            2,
            "blank line before more voxels; blank lines are allowed only at the end of the file",
        ),
        (
            b"x,y,z\n1,2,3\n",
            1,
            "x = 'x' is not a whole number; expected three non-negative integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n1,,3\n",
            2,
            "y is empty in '1,,3'; expected three non-negative integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n1,2,3x\n",
            2,
            "z = '3x' is not a whole number; expected three non-negative integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n1,2,+3\n",
            2,
            "z = '+3' is not a whole number; expected three non-negative integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n1,2 2,3\n",
            2,
            "y = '2 2' is not a whole number; expected three non-negative integers x,y,z separated by commas",
        ),
        (b"1,2,3\n2147483648,0,0\n", 2, "x = 2147483648 is too large; expected at most 2147483647"),
        (
            b"1,2,3\n\x00\x01\x02\n",
            2,
            "binary data, not text; expected three non-negative integers x,y,z separated by commas",
        ),
        (
            b"1,2,3\n\xff\xfe,1,1\n",
            2,
            "binary data, not text; expected three non-negative integers x,y,z separated by commas",
        ),
    ],
)
def test_malformed_lines_name_file_line_and_expectation(tmp_path, data, line, message):
    path = write(tmp_path, data)
    with pytest.raises(InputFileError) as caught:
        load_voxels(path)
    assert str(caught.value) == f"{path}:{line}: {message}"
    assert caught.value.line == line


def test_a_long_bad_line_is_quoted_short_and_the_expectation_kept(tmp_path):
    # A CSV table read as a voxel list: its header is thousands of characters long.
    header = ",".join(f"column_{i}" for i in range(300))
    path = write(tmp_path, f"{header}\n1,2,3\n".encode())
    with pytest.raises(InputFileError) as caught:
        load_voxels(path)
    message = str(caught.value)
    assert message.startswith(f"{path}:1: 300 comma-separated values in 'column_0,column_1,")
    assert f"... ({len(header)} characters)'" in message
    assert message.endswith("; expected three non-negative integers x,y,z separated by commas")
    assert len(message) < 200 + len(str(path))


def test_a_long_bad_value_is_quoted_short(tmp_path):
    path = write(tmp_path, b"1,2,3\n" + b"a" * 5000 + b",2,3\n")
    with pytest.raises(InputFileError) as caught:
        load_voxels(path)
    assert str(caught.value).endswith(
        "x = 'aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa... (5000 characters)' "
        "is not a whole number; expected three non-negative integers x,y,z separated by commas"
    )


def test_error_line_number_counts_from_the_start_deep_in_a_large_file(tmp_path):
    lines = [f"{i},{i % 7},{i % 11}\n" for i in range(100_000)]
    lines[87_654] = "5,6\n"
    path = write(tmp_path, "".join(lines).encode())
    with pytest.raises(InputFileError, match=rf"^{path}:87655: 2 comma-separated values in '5,6'"):
        load_voxels(path)


def test_missing_file_is_named(tmp_path):
    path = tmp_path / "nowhere.txt"
    with pytest.raises(InputFileError) as caught:
        load_voxels(path)
    assert str(caught.value) == f"{path}: no such file; expected a voxel-list file"


def test_folder_instead_of_file(tmp_path):
    with pytest.raises(InputFileError, match="is a folder"):
        load_voxels(tmp_path)


def test_duplicates_are_removed_keeping_first_occurrence_order(tmp_path):
    path = write(tmp_path, b"5,5,5\n1,2,3\n5,5,5\n0,0,0\n1,2,3\n1,2,4\n")
    voxels, dropped = load_voxels_counted(path)
    np.testing.assert_array_equal(voxels, [[5, 5, 5], [1, 2, 3], [0, 0, 0], [1, 2, 4]])
    assert dropped == 2


def test_unique_voxels_agrees_with_numpy_unique_on_random_data():
    rng = np.random.default_rng(7)
    voxels = rng.integers(0, 40, size=(50_000, 3)).astype(np.int32)
    kept, dropped = unique_voxels(voxels)
    expected_rows, first = np.unique(voxels, axis=0, return_index=True)
    np.testing.assert_array_equal(kept, voxels[np.sort(first)])
    assert dropped == len(voxels) - len(expected_rows)


def test_unique_voxels_with_keys_too_large_to_pack():
    big = 2**31 - 1
    voxels = np.array([[big, big, big], [0, 1, 2], [big, big, big]], dtype=np.int32)
    kept, dropped = unique_voxels(voxels)
    np.testing.assert_array_equal(kept, [[big, big, big], [0, 1, 2]])
    assert dropped == 1


def test_save_is_atomic_when_the_data_is_bad(tmp_path):
    path = tmp_path / "keep.txt"
    path.write_text("1,2,3\n")
    with pytest.raises(FieldError, match=r"^voxels\[0\] = \(1, -2, 3\)"):
        save_voxels(path, np.array([[1, -2, 3]]))
    with pytest.raises(FieldError, match=r"^voxels is an array of float64"):
        save_voxels(path, np.array([[1.5, 2, 3]]))
    with pytest.raises(FieldError, match=r"^voxels is an array of shape \(3,\)"):
        save_voxels(path, np.array([1, 2, 3]))
    with pytest.raises(FieldError, match=r"^ids = \[1, 2\]"):
        save_voxels(path, np.array([[1, 2, 3]]), ids=[1, 2])
    assert path.read_text() == "1,2,3\n"
    assert os.listdir(tmp_path) == ["keep.txt"]


def test_a_voxel_list_that_cannot_be_written_is_named_as_itself(tmp_path):
    # The error was an IsADirectoryError naming the temporary file beside the folder.
    with pytest.raises(OutputFileError) as caught:
        save_voxels(tmp_path, np.array([[1, 2, 3]]))
    assert str(caught.value) == f"{tmp_path}: cannot be written (is a directory)"
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: load_voxels(None), "path is not set: expected a voxel-list file's path"),
        (lambda: save_voxels(7, [[1, 2, 3]]), "path = 7: expected a voxel-list file's path"),
        (lambda: load_target(None), "path is not set: expected a target model file's path"),
        (lambda: Scene.load(None, 0.5), "scene_path is not set: expected a scene model file's path"),
    ],
)
def test_a_path_that_is_no_path_is_a_field_error(call, message):
    # They raised TypeError from pathlib.
    with pytest.raises(FieldError) as caught:
        call()
    assert str(caught.value) == f"{message} (str or pathlib.Path)"


def test_python_and_compiled_formatting_agree(monkeypatch):
    from ladartui.scene import voxels as module

    rng = np.random.default_rng(5)
    voxels = rng.integers(0, 2**31 - 1, size=(3000, 3))
    voxels[:10] = rng.integers(0, 12, size=(10, 3))  # short numbers too
    expected = "".join(f"{x},{y},{z}\n" for x, y, z in voxels.tolist()).encode()
    assert bytes(module.format_voxel_lines(voxels)) == expected
    monkeypatch.setattr(module, "_COMPILED_FORMAT_ROWS", 0)
    assert bytes(module.format_voxel_lines(voxels)) == expected


def test_sorted_lists_skip_the_duplicate_search_but_still_find_repeats():
    sorted_rows = np.array([[0, 0, 1], [0, 0, 2], [0, 1, 0], [3, 0, 0]], dtype=np.int32)
    kept, dropped = unique_voxels(sorted_rows)
    np.testing.assert_array_equal(kept, sorted_rows)
    assert dropped == 0
    repeated = np.array([[0, 0, 1], [0, 0, 1], [0, 1, 0]], dtype=np.int32)  # sorted, not strictly
    kept, dropped = unique_voxels(repeated)
    np.testing.assert_array_equal(kept, [[0, 0, 1], [0, 1, 0]])
    assert dropped == 1


def test_plain_lines_and_the_compiled_checker_read_the_same_voxels(tmp_path, monkeypatch):
    from ladartui.scene import voxels as module

    rng = np.random.default_rng(3)
    voxels = rng.integers(0, 3000, size=(5000, 3))
    voxels[:5] = [[0, 0, 0], [2**31 - 1, 7, 0], [9, 10, 99], [5, 5, 5], [0, 0, 0]]
    text = "".join(f"{x},{y},{z}\n" for x, y, z in voxels.tolist())
    for ending in (text, text[:-1]):  # with and without the final newline
        path = write(tmp_path, ending.encode())
        expected, first = np.unique(voxels, axis=0, return_index=True)
        plain = load_voxels(path)
        np.testing.assert_array_equal(plain, voxels[np.sort(first)])
        monkeypatch.setattr(module, "_PLAIN_BYTES", 0)  # force the compiled pass
        np.testing.assert_array_equal(load_voxels(path), plain)
        monkeypatch.undo()


def test_reading_a_plain_file_does_not_import_numba(tmp_path):
    import subprocess
    import sys

    path = write(tmp_path, b"1,2,3\n4,5,6\n")
    code = (
        "import sys; from ladartui.scene.voxels import load_voxels; "
        f"assert load_voxels({str(path)!r}).shape == (2, 3); print('numba' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_load_voxels_of_a_target_model_with_ids_says_what_reads_it(tmp_path):
    """save_voxels(path, voxels, ids) writes x,y,z,id lines, as the bundled convoy's target
    model has them; load_voxels called the file a mistake: "4 comma-separated values in
    '1,2,3,1'; expected three non-negative integers x,y,z", with nothing on reading it."""
    path = tmp_path / "t_Target.txt"
    voxels = np.array([[1, 2, 3], [4, 5, 6]], dtype=np.int32)
    save_voxels(path, voxels, ids=[1, 2])
    with pytest.raises(InputFileError) as caught:
        load_voxels(path)
    assert str(caught.value) == (
        f"{path}:1: 4 comma-separated values in '1,2,3,1' (a target model's x,y,z,id lines, "
        "which ladartui.scene.target_model.load_target reads with their ids); expected three "
        "non-negative integers x,y,z separated by commas"
    )
    read, ids = load_target(path)
    assert read.tolist() == voxels.tolist() and ids.tolist() == [1, 2]
