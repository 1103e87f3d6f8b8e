"""Reading the TOML file and the generic value checks whose messages name the file, the dotted key,
the value given and what is allowed."""

from __future__ import annotations

import os
import re
import stat
import tomllib
from pathlib import Path

from fracid.config.schema import ConfigError
from fracid.settings import checks as settings
from fracid.settings.checks import SettingError, bytes_text, show

__all__ = ["Checker", "MAX_CONFIG_BYTES", "STDIN", "bytes_text", "read_toml", "show"]


class Checker:
    """Raises ConfigError messages naming the file, the dotted key, the value and what is allowed."""

    def __init__(self, path: Path):
        self.path = path
        self.warnings: list[str] = []

    def fail(self, key: str, value, allowed: str):
        raise ConfigError(f"{self.path}: {key} = {show(value)}: {allowed}")

    def warn(self, text: str) -> None:
        """Record a warning (a valid value that is probably not what was meant), once."""
        if text not in self.warnings:
            self.warnings.append(text)

    def missing(self, key: str, allowed: str):
        raise ConfigError(f"{self.path}: {key} is missing (no value given); it is required: {allowed}")

    def checked(self, check, *args):
        """``check(*args)`` (a checker of :mod:`fracid.settings.checks`), its SettingError as this file's
        ConfigError."""
        try:
            return check(*args)
        except SettingError as err:
            self.fail(err.key, err.value, err.allowed)

    def table(self, key: str, value, allowed_keys) -> dict:
        """``value``, a table with keys among ``allowed_keys`` (:func:`fracid.settings.checks.table`)."""
        return self.checked(settings.table, key, value, allowed_keys)

    def number(self, key, value, allowed="must be a number", ok=lambda v: True) -> float:
        """A finite number (not a bool) with ``ok(value)`` (:func:`fracid.settings.checks.number`)."""
        return self.checked(settings.number, key, value, allowed, ok)

    def integer(self, key, value, allowed="must be an integer", ok=lambda v: True) -> int:
        """An int (not a bool) with ``ok(value)`` (:func:`fracid.settings.checks.integer`)."""
        return self.checked(settings.integer, key, value, allowed, ok)

    def string(self, key, value, allowed="must be a string") -> str:
        if not isinstance(value, str) or not value:
            self.fail(key, value, allowed)
        return value

    def choice(self, key, value, choices) -> str:
        """One of the strings ``choices`` (:func:`fracid.settings.checks.choice`)."""
        return self.checked(settings.choice, key, value, choices)

    def pair(self, key, value, allowed) -> tuple[float, float]:
        """Two finite numbers [a, b]; any defect names the whole list."""
        if not (isinstance(value, list) and len(value) == 2) or not all(settings.is_number(v) for v in value):
            self.fail(key, value, allowed)
        return float(value[0]), float(value[1])

    def strings(self, key, value, what="column names") -> tuple:
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            self.fail(key, value, f"must be a list of {what} (strings)")
        duplicates = sorted({v for v in value if value.count(v) > 1})
        if duplicates:
            self.fail(key, value, f"must not repeat a name; repeated: {', '.join(map(repr, duplicates))}")
        return tuple(value)

    def location(self, key, value, base: Path, allowed="must be a path (string)") -> Path:
        """``value`` as an absolute path (``~`` expanded, relative to ``base``, links resolved); a NUL byte
        or a symbolic-link loop named."""
        self.string(key, value, allowed)
        if "\0" in value:
            self.fail(key, value, "a path cannot contain a NUL byte (\\0)")
        given = Path(value).expanduser()
        try:
            return (given if given.is_absolute() else base / given).resolve()
        except (OSError, RuntimeError) as err:  # RuntimeError: a symbolic-link loop (Python < 3.13)
            self.fail(key, value, f"cannot be resolved ({err}): a symbolic link that points to itself?")

    def file(self, key, value, base: Path) -> Path:
        resolved = self.location(key, value, base, "must be a file path (string)")
        given = Path(value).expanduser()
        where = f"{resolved}" if given.is_absolute() else f"resolved relative to the config file: {resolved}"
        if not resolved.exists():
            self.fail(key, value, f"file not found ({where})")
        if not resolved.is_file():
            self.fail(key, value, f"not a file ({where})")
        if resolved == self.path:
            self.fail(key, value, f"this is the configuration itself ({where}), a TOML file, not the data file "
                                  "this key names: give the file of the measurements")
        if looks_like_toml(resolved):
            self.fail(key, value, f"this is a TOML file ({where}), a configuration?, not the data file this key "
                                  "names: give the file of the measurements")
        return resolved


#: a TOML table header line: ``[model]``, ``[[experiments]]``, ``[identify.bounds]``
_TABLE_HEADER = re.compile(r"^\[\[?\s*[A-Za-z_][\w.-]*\s*\]\]?\s*(#.*)?$")
_TOML_KEY = re.compile(r"^[A-Za-z_][\w-]*\s*=")


def looks_like_toml(path: Path, head: int = 4096) -> bool:
    """Whether the file at ``path`` is TOML rather than a data table: its name ends in ``.toml``, or its first
    ``head`` bytes hold a table header line (``[model]``) before any other line, then a ``key =`` line."""
    if path.suffix.lower() == ".toml":
        return True
    try:
        with open(path, "rb") as handle:
            lines = handle.read(head).decode("utf-8", "replace").splitlines()
    except OSError:
        return False
    lines = [line.strip() for line in lines if line.strip() and not line.lstrip().startswith("#")]
    return bool(lines) and bool(_TABLE_HEADER.match(lines[0])) and any(_TOML_KEY.match(line) for line in lines[1:])


#: the largest configuration file read [bytes]: a configuration is a few KiB; more is not one
MAX_CONFIG_BYTES = 1 << 20

#: the name of a configuration read from standard input (``fracid identify -``)
STDIN = "-"


def read_toml(path: Path, stdin=None) -> dict:
    """The TOML table of ``path`` (``stdin``: the bytes read from standard input instead); a path that is
    not a regular file (a FIFO, a device, a directory), a file too large to be a configuration, text that
    is not UTF-8 or not TOML, each raise a ConfigError naming the file."""
    try:
        raw = stdin if stdin is not None else _config_bytes(path)
        if len(raw) > MAX_CONFIG_BYTES:
            raise ConfigError(f"{path}: more than {MAX_CONFIG_BYTES:,} bytes: too large for a configuration")
        # a byte-order mark (Windows Notepad) is not TOML but says nothing wrong about the file
        return tomllib.loads(raw.removeprefix(b"\xef\xbb\xbf").decode("utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"{path}: configuration file not found") from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a directory, not a configuration file") from None
    except UnicodeDecodeError as err:
        raise ConfigError(f"{path}: not a UTF-8 text file ({err})") from None
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{path}: not valid TOML: {err}") from None
    except RecursionError:
        raise ConfigError(f"{path}: not a usable configuration: its tables or arrays are nested too deeply "
                          "(a fracid configuration nests at most three levels)") from None


def _config_bytes(path: Path) -> bytes:
    """The bytes of a regular file of at most MAX_CONFIG_BYTES; checked before reading, so that a FIFO
    (which would block) or a device such as /dev/zero (which never ends) is refused at once."""
    with open(path, "rb", opener=lambda name, flags: os.open(name, flags | getattr(os, "O_NONBLOCK", 0))) as handle:
        info = os.fstat(handle.fileno())
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError(path)
        if not stat.S_ISREG(info.st_mode):
            raise ConfigError(f"{path}: not a regular file (a pipe, a device or a socket): give the configuration "
                              f"as a file, or as '{STDIN}' to read it from standard input")
        if info.st_size > MAX_CONFIG_BYTES:
            raise ConfigError(f"{path}: {info.st_size:,} bytes: too large for a configuration file (at most "
                              f"{MAX_CONFIG_BYTES:,}); is it the configuration?")
        return handle.read(MAX_CONFIG_BYTES + 1)
