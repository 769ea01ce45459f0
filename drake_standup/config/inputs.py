"""The files and folders a user names: each one checked before anything simulates.

Every failure is a ScenarioError: one line naming the option or key, the path, and what
it accepts.
"""

from pathlib import Path

from drake_standup.config.errors import ScenarioError


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
