"""Model files as users name them: ``zoo:NAME`` (a shipped model) or a path to a ``.zip``.

``surveil play``, ``evaluate``, tournament specs and training opponents all take these
names; :func:`model_policy_name` turns one into the registry's ``ROLE/sb3:PATH``
(:func:`strategies.policies.make_policy`) after checking the file, and the role its
``provenance.json`` records. Light on purpose (no numpy, no policy imported): the CLI
and the tournament spec check names before anything heavy loads.

Examples:
    >>> is_model_reference("zoo:ppo_evader_vs_greedy_open_room"), is_model_reference("m.zip")
    (True, True)
    >>> is_model_reference("evader/sb3:m.zip"), is_model_reference("evader/straight")
    (False, False)
    >>> model_policy_name("evader/straight", "evader", "opponent")
    'evader/straight'
"""

from __future__ import annotations

import importlib.util
import json
import os
import warnings
import zipfile
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from envs.errors import InvalidConfigError

__all__ = [
    "NoProvenanceWarning",
    "absolute_model_name",
    "check_model_input",
    "is_model_reference",
    "model_input_shape",
    "model_path",
    "model_policy_name",
    "read_provenance",
    "zoo_dir",
]

_SB3 = "sb3:"
"""The registry's prefix of a model file's kind (``ROLE/sb3:PATH``)."""


class NoProvenanceWarning(UserWarning):
    """A model file has no ``provenance.json`` beside it: the role it was trained for
    and the observation it was trained on are unknown, so neither is checked (only the
    input shape its zip records: :func:`check_model_input`)."""


def warn_no_provenance(what: str, path: Path) -> None:
    """Warn (:class:`NoProvenanceWarning`) that the model ``what`` names, at ``path``,
    has no ``provenance.json`` beside it."""
    warnings.warn(
        f"{what}: no provenance.json beside {path}: the role and the observation this "
        "model was trained for are unknown and unchecked (a model of the other role plays "
        "without a word, and so does one given another observation of the size it takes; "
        "only observations of another size are refused); put the provenance.json its "
        "training wrote beside it",
        NoProvenanceWarning,
        stacklevel=3,
    )


def zoo_dir() -> Path | None:
    """The shipped model zoo's directory (``training/zoo/models``), found without
    importing ``training`` (the layers keep ``strategies`` below it)."""
    spec = importlib.util.find_spec("training")
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations))) / "zoo" / "models"


def is_model_reference(text: str) -> bool:
    """Whether ``text`` names a model file the way users do: ``zoo:NAME`` or a path
    ending in ``.zip`` (not the registry's ``ROLE/sb3:PATH``)."""
    if text.startswith((f"pursuer/{_SB3}", f"evader/{_SB3}")):
        return False
    return text.startswith("zoo:") or text.lower().endswith(".zip")


def absolute_model_name(text: str) -> str:
    """``text`` with a relative model file path made absolute against the current
    directory (a ``.zip`` or the registry's ``ROLE/sb3:PATH``; ``zoo:NAME`` and policy
    names unchanged), for a run's stored config: a rerun from another directory then
    plays the same file.

    Examples:
        >>> import os
        >>> absolute_model_name("m.zip") == os.path.join(os.getcwd(), "m.zip")
        True
        >>> absolute_model_name("zoo:x"), absolute_model_name("evader/straight")
        ('zoo:x', 'evader/straight')
        >>> absolute_model_name("evader/sb3:/models/m.zip")
        'evader/sb3:/models/m.zip'
    """
    role, sep, path = text.partition(f"/{_SB3}")
    if sep and path and role in ("pursuer", "evader"):
        return f"{role}{sep}{os.path.abspath(path)}"
    if is_model_reference(text) and not text.startswith("zoo:"):
        return os.path.abspath(text)
    return text


def model_path(text: str, what: str, base: Path | None = None) -> Path:
    """The model file ``text`` names: ``zoo:NAME`` (a shipped model) or a path (relative
    to ``base``, default the current directory), checked to be an SB3 model zip.

    Args:
        text: ``zoo:NAME`` or a path.
        what: how the caller names the value, the start of every message
            (``"opponent = 'zoo:x'"``).
        base: the directory a relative path is relative to.

    Raises:
        InvalidConfigError: no such zoo model (listing them) or file, or not a model zip.
    """
    if text.startswith("zoo:"):
        name = text[len("zoo:") :]
        root = zoo_dir()
        path = None if root is None or not name else root / name / "model.zip"
        if path is None or not path.is_file():
            known = sorted(p.name for p in root.iterdir()) if root and root.is_dir() else []
            raise InvalidConfigError(f"{what}: no zoo model {name!r}; known: {known}")
    else:
        path = ((Path.cwd() if base is None else base) / text).resolve()
        if not path.is_file():
            raise InvalidConfigError(f"{what}: no such file ({path})")
    try:  # SB3's zip has a "data" entry (checked here, not at the first episode's reset)
        with zipfile.ZipFile(path) as zf:
            zf.getinfo("data")
    except (OSError, KeyError, zipfile.BadZipFile) as exc:
        raise InvalidConfigError(f"{what}: not a stable-baselines3 model zip ({exc})") from None
    return path


def model_input_shape(path: Path) -> tuple[int, ...] | None:
    """The shape of the observations the SB3 model zip at ``path`` takes, as its
    ``data`` entry records it (without loading torch), or None when it records none
    (another space than a Box, or an older format).

    Raises:
        InvalidConfigError: the file is not a zip with a readable JSON ``data`` entry.
    """
    try:
        with zipfile.ZipFile(path) as zf:
            data = json.loads(zf.read("data"))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile) as exc:
        raise InvalidConfigError(f"{path}: not a stable-baselines3 model zip ({exc})") from None
    space = data.get("observation_space") if isinstance(data, dict) else None
    shape = space.get("_shape") if isinstance(space, dict) else None
    if not isinstance(shape, list) or not all(
        isinstance(n, int) and not isinstance(n, bool) for n in shape
    ):
        return None
    return tuple(shape)


def check_model_input(
    path: Path,
    observations: Iterable[Mapping[str, Any]],
    what: str,
    *,
    given_by: str,
    then: str,
) -> None:
    """Refuse the SB3 model zip at ``path`` if any of the ``observations`` it would be
    given has another shape than the one its ``data`` entry records (read without
    torch): without this, it plays until its first ``act()`` and fails there (a lidar
    model without its provenance.json given the env's state).

    Args:
        path: the model zip.
        observations: observation settings, each a mapping of ``observation`` (the kind)
            and ``n_rays`` (read for a lidar), as ``EnvConfig`` names them.
        what: how the caller names the model, the start of the message.
        given_by: whose observation it is, as the message says it (``"the game's"``).
        then: what would happen and how to put it right, the end of the message.

    Raises:
        InvalidConfigError: naming ``what``, the model, its input shape and the one given.
    """
    want = model_input_shape(path)
    if want is None:
        return
    from envs.surveillance.observations import observation_size

    for opts in observations:
        kind = opts["observation"]
        given = (observation_size(kind, int(opts.get("n_rays", 0))),)
        if given != want:
            told = f"observation {kind!r}"
            if kind != "state":
                told += f" with n_rays = {int(opts['n_rays'])}"
            raise InvalidConfigError(
                f"{what}: model {path} takes observations of shape {want}, but {given_by} "
                f"{told} has shape {given}: {then}"
            )


def model_policy_name(text: str, role: str, what: str) -> str:
    """A policy name as users write it, as the registry's name: ``zoo:NAME`` or a model
    ``.zip`` becomes ``ROLE/sb3:PATH`` (the file checked, and the role its
    ``provenance.json`` records); any other name is returned unchanged.

    Raises:
        InvalidConfigError: no such model, not a model zip, or a model trained as the
            other role (the message starts with ``what``).
    """
    if not is_model_reference(text):
        return text
    path = model_path(text, what)
    provenance = read_provenance(path)
    if provenance is None:
        warn_no_provenance(what, path)
    trained = (provenance or {}).get("role")
    if trained is not None and trained != role:
        raise InvalidConfigError(
            f"{what}: this model was trained as the {trained} (its provenance.json says "
            f"role = {trained!r}); it cannot play the {role}"
        )
    return f"{role}/{_SB3}{path}"


def read_provenance(path: Path) -> dict[str, Any] | None:
    """The ``provenance.json`` beside a model zip, or None if there is none.

    Raises:
        InvalidConfigError: it exists but is not a JSON object (naming the file).
    """
    prov = Path(path).parent / "provenance.json"
    if not prov.is_file():
        return None
    try:
        data = json.loads(prov.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InvalidConfigError(f"{prov}: unreadable provenance ({exc})") from exc
    if not isinstance(data, dict):
        raise InvalidConfigError(f"{prov}: expected a JSON object, got {type(data).__name__}")
    return data
