import pytest

from roto.result_files import read_json
from roto.text_files import read_text
from roto.yaml_files import read_yaml


def test_a_text_file_reads_as_utf8(tmp_path):
    path = tmp_path / "page.md"
    path.write_bytes("rotations per 10 s — round\n".encode())
    assert read_text(path, "page") == "rotations per 10 s — round\n"


def test_a_missing_file_a_folder_and_a_binary_file_are_errors_naming_the_role_and_the_path(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"^page '.*missing\.md' does not exist$"):
        read_text(tmp_path / "missing.md", "page")
    with pytest.raises(ValueError, match=rf"^submission '{tmp_path}' cannot be read: it is a folder; give a file$"):
        read_text(tmp_path, "submission", "JSON")
    binary = tmp_path / "image.png"
    binary.write_bytes(b"ab\x89PNG")
    with pytest.raises(ValueError, match=r"^page '.*image\.png' is not text: byte 2 \(0x89\) is not UTF-8"):
        read_text(binary, "page")
    with pytest.raises(ValueError, match=r"is not JSON text: byte 2 \(0x89\)"):
        read_text(binary, "summary", "JSON")


def test_json_and_yaml_readers_give_the_same_errors_for_a_folder(tmp_path):
    for read, what in ((read_json, "submission"), (read_yaml, "plan")):
        with pytest.raises(ValueError, match=rf"^{what} '{tmp_path}' cannot be read: it is a folder; give a file$"):
            read(tmp_path, what)
