"""Why an input path cannot be read as a file, in words, without raising; path_field:
a path argument that is no path (None, a number) as a FieldError."""

import errno
import os
import re
from pathlib import Path

from ladartui.errors import FieldError, InputFileError, os_reason

SPECIAL_FILE = "is not a regular file (a pipe or device)"
FOLDER = "is a folder, expected a file"  # file_problem's words for a folder
NO_SUCH_FILE = "no such file"  # an input file that is missing, in every reader's words


# The files of other kinds a command may be given (or name) where it takes a voxel list.
OTHER_FILE_KINDS = {
    ".toml": "a scenario",
    ".las": "a LAS point cloud",
    ".laz": "a LAS point cloud",
    ".cmf": "a measures file",
    ".obj": "a mesh",
    ".stl": "a mesh",
    ".ply": "a mesh",
}


def other_file_kind(path) -> str | None:
    """What a file of ``path``'s suffix is when that is no voxel list ("a mesh"), else None."""
    return OTHER_FILE_KINDS.get(Path(path).suffix.lower())


def path_field(name, value, what: str) -> Path:
    """``value`` as a Path when it is a str or os.PathLike (not bytes); else FieldError
    expecting ``what`` ("a scenario file's path")."""
    if not isinstance(value, (str, os.PathLike)) or isinstance(value, bytes):
        raise FieldError(name, value, f"{what} (str or pathlib.Path)")
    return Path(value)


def user_path(path) -> Path:
    """``path`` with a leading ``~`` or ``~user`` made that home, as the shell makes it;
    as it is where there is no such home (pathlib's ``expanduser`` raised RuntimeError
    there, a traceback for a typing slip)."""
    return Path(os.path.expanduser(os.fspath(path)))


def absolute_path(path) -> Path:
    """``path`` (``~`` made a home, as ``user_path`` does) made absolute against the
    working folder and normalised (``..`` and ``.`` taken out), so that the same file is
    named the same wherever it is named from."""
    return Path(os.path.normpath(user_path(path).absolute()))


def file_problem(path: Path) -> str | None:
    """None when ``path`` is a regular file; else what is wrong ("not found", "is a folder", ...)."""
    try:
        if Path(path).is_file():
            return None
        if Path(path).is_dir():
            return FOLDER
        if Path(path).exists():
            return SPECIAL_FILE
        if os.path.islink(path):  # a link that loops is there, unlike one to a missing file
            try:
                os.stat(path)
            except OSError as error:
                if error.errno == errno.ELOOP:
                    raise
        return "not found"
    except OSError as error:
        if error.errno == errno.ENAMETOOLONG:
            return f"name too long for this system (at most {_name_max(path)} characters a name)"
        return f"cannot be read ({os_reason(error)})"


# A line ends at LF, CR LF or CR alone, and nothing else (text_lines, not_utf8).
_LINE_END = re.compile(r"\r\n|\r|\n")
_LINE_END_BYTES = re.compile(_LINE_END.pattern.encode("ascii"))


def not_utf8(data: bytes, error: UnicodeDecodeError) -> tuple[int, str]:
    """Where ``data`` stops being UTF-8 text: the line (from 1, as ``text_lines`` numbers
    them) and "not UTF-8 text (byte 0xNN)"."""
    line = len(_LINE_END_BYTES.findall(data, 0, error.start)) + 1
    return line, f"not UTF-8 text (byte 0x{data[error.start]:02x})"


def text_lines(text: str) -> list[str]:
    """The lines of a file's ``text`` as an editor numbers them: ended by LF, CR LF or CR
    alone, and by nothing else. ``str.splitlines`` also ends one at a form feed, at
    U+0085 (Windows' '...' read as Latin-1) and at U+2028/U+2029, which a comment pasted
    from a document may hold: every line below would be named one too far on."""
    lines = _LINE_END.split(text)
    if lines[-1] == "":  # the final line end ends a line; it starts none
        lines.pop()
    return lines


def read_utf8(path, expected: str) -> str:
    """The text of ``path`` (a byte order mark dropped); a pipe or device is refused
    unread (``refuse_special_file``) and bytes that are not UTF-8 raise "PATH:LINE: not
    UTF-8 text (byte 0xNN); ``expected``", a folder "PATH: is a folder; ``expected``".
    Any other OSError is the caller's."""
    refuse_special_file(path, expected)  # a pipe would wait for ever
    try:
        data = Path(path).read_bytes()
    except IsADirectoryError:
        raise InputFileError(path, f"is a folder; {expected}") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        line, problem = not_utf8(data, error)
        raise InputFileError(path, f"{problem}; {expected}", line) from None


def _name_max(path: Path) -> int:
    try:
        return os.pathconf(Path(path).anchor or ".", "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def other_code_points(path) -> str:
    """ "; the folder holds NAME, ..." when a file beside ``path`` has its name in other
    Unicode code points (an accent as a letter and a combining mark, as macOS writes
    names, against one code point as typed): the same on screen, so "not found" alone
    named a file that ``ls`` shows; else ""."""
    import unicodedata

    path = Path(path)
    wanted = unicodedata.normalize("NFC", path.name)
    try:
        with os.scandir(path.parent) as entries:
            for entry in entries:
                if entry.name != path.name and unicodedata.normalize("NFC", entry.name) == wanted:
                    return (
                        f"; the folder holds {entry.name}, the same name in other Unicode code "
                        "points (accents as separate marks, as macOS writes names): rename that "
                        "file to the name written here"
                    )
    except OSError:
        pass
    return ""


def no_such_file(path) -> str:
    """ "no such file", every reader's words for a missing input, with ``other_code_points``'
    hint where a file beside ``path`` has its name in other code points."""
    return NO_SUCH_FILE + other_code_points(path)


def require_file(path, expected: str) -> None:
    """``refuse_special_file``, "PATH: is a folder; ``expected``", and "PATH: no such file;
    ``expected``" for anything else that is no regular file, from one look (for readers
    that ask before opening)."""
    problem = file_problem(Path(path))
    if problem == SPECIAL_FILE:
        raise InputFileError(path, f"{SPECIAL_FILE}; {expected}")
    if problem == FOLDER:
        raise InputFileError(path, f"is a folder; {expected}")
    if problem:
        said = no_such_file(path) if problem == "not found" else problem  # (a link that loops)
        raise InputFileError(path, f"{said}; {expected}")


def refuse_special_file(path, expected: str) -> None:
    """``InputFileError`` "PATH: is not a regular file (a pipe or device); ``expected``"
    for a pipe or device: opening a pipe waits for a writer, so check before opening."""
    if file_problem(Path(path)) == SPECIAL_FILE:
        raise InputFileError(path, f"{SPECIAL_FILE}; {expected}")
