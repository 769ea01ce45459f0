"""The files, folders and robot names a user gives: each one checked before anything
simulates.

Every failure is a ScenarioError: one line naming the option or key, the value, and what
it accepts. The entry points check their options here (--scenario and a sweep file
through read_text_file, --out through check_output_dir).
"""

from pathlib import Path

from drake_standup.config.errors import ScenarioError

# --- Files and folders -------------------------------------------------------------------


def read_text_file(path: Path | str, key: str, accepted: str) -> str:
    """The text of the file at path (UTF-8, with or without a byte order mark); an error
    naming key if the file is missing, a folder, unreadable or not UTF-8 text. accepted:
    what key accepts, for the message."""
    path = Path(path)
    if path.is_dir():
        raise ScenarioError(f"{key}: '{path}' is a folder; accepted: {accepted}")
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(f"{key}: file '{path}' not found; accepted: {accepted}") from None
    except OSError as err:
        raise ScenarioError(
            f"{key}: '{path}' cannot be read ({err.strerror}); accepted: a file this user can read"
        ) from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = err.object[: err.start].count(b"\n") + 1
        raise ScenarioError(
            f"{key}: '{path}' is not UTF-8 text (byte 0x{err.object[err.start]:02x} on line "
            f"{line}); accepted: a text file saved as UTF-8"
        ) from None


def check_output_dir(path: Path | str, key: str = "--out") -> Path:
    """The output folder, created if missing; an error if it cannot be one (a file is in
    the way, or the folder cannot be created)."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise ScenarioError(f"{key}: '{path}' is a file; accepted: a folder") from None
    except NotADirectoryError:
        raise ScenarioError(
            f"{key}: '{path}' lies under a file; accepted: a folder path whose parents are folders"
        ) from None
    except OSError as err:
        raise ScenarioError(
            f"{key}: '{path}' cannot be created ({err.strerror}); accepted: a writable folder"
        ) from None
    return path
