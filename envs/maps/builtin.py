"""Built-in maps by name, with a description and recommended parameters.

The geometry lives in ``envs/maps/data/NAME.json`` (our JSON schema, see
:mod:`envs.maps.io`), shipped as package data and read with :mod:`importlib.resources`.
Each file's ``metadata`` holds the recommended parameters ``l_min``, ``l_max``,
``v_pursuer`` and ``v_evader``. Adding a world is adding a file.

The paper's worlds follow THEORY.md section 3 [ASM] (L = L_min = 2, corridor width 1 < L,
corridors longer than 2L):

* ``corridor`` (Fig. 3): room [0, 10] x [-5, 5] with the dead-end corridor
  [-6, 0] x [-0.5, 0.5], as one non-convex boundary;
* ``two_rooms`` (Fig. 6): the same plus the room [-16, -6] x [-5, 5] at the corridor's
  other end;
* ``corner`` (Fig. 9b): an L-shaped hall with a single convex obstacle vertex.

The others exercise other features: ``open_room`` (no obstacle), ``pillars`` (convex
pillars of several shapes), ``l_hall`` (a wide L with a pillar), ``maze`` (corridors 2.5
wide around free-standing walls) and ``office`` (rooms joined by doors 2 wide).
The recommended speeds give rho = V_e / V_p = 0.5, the ratio of THEORY.md section 7's
reference values; L_max = 2 L_min.
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass, field
from importlib import resources

from envs import validation
from envs.errors import InvalidConfigError, InvalidMapError, UnknownNameError
from envs.maps.io import map_from_dict
from envs.maps.map import Map

__all__ = ["MapInfo", "builtin_info", "builtin_map", "builtin_names"]

_PARAMS = ("l_min", "l_max", "v_pursuer", "v_evader")


@dataclass(frozen=True)
class MapInfo:
    """A built-in map with its description and recommended parameters.

    Attributes:
        name: the registry name (also the map's name).
        description: one line.
        l_min: recommended minimum rod length L_min (the paper's L for the decomposition).
        l_max: recommended maximum sensor range L_max.
        v_pursuer: recommended pursuer speed bound V_p.
        v_evader: recommended evader speed bound V_e.
        map: the map itself.
    """

    name: str
    description: str
    l_min: float
    l_max: float
    v_pursuer: float
    v_evader: float
    map: Map = field(repr=False, compare=False)

    @property
    def L_min(self) -> float:
        """Alias of :attr:`l_min` in the paper's notation."""
        return self.l_min

    @property
    def L_max(self) -> float:
        """Alias of :attr:`l_max` in the paper's notation."""
        return self.l_max

    @property
    def rho(self) -> float:
        """Speed ratio rho = V_e / V_p (Sec. 6)."""
        return self.v_evader / self.v_pursuer

    def params(self) -> dict[str, float]:
        """The recommended parameters as keyword arguments (``l_min=..., ...``)."""
        return {k: getattr(self, k) for k in _PARAMS}


def _data_dir():
    return resources.files("envs.maps").joinpath("data")


@functools.cache
def _names() -> tuple[str, ...]:
    names = [p.name[: -len(".json")] for p in _data_dir().iterdir() if p.name.endswith(".json")]
    return tuple(sorted(names))


def builtin_names() -> list[str]:
    """Names of the built-in maps, sorted."""
    return list(_names())


@functools.cache
def _load(name: str) -> MapInfo:
    source = f"envs/maps/data/{name}.json"
    text = _data_dir().joinpath(f"{name}.json").read_text(encoding="utf-8")
    try:
        obj = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InvalidMapError(f"{source}: not valid JSON ({exc})") from exc
    doc = map_from_dict(obj, source=source)
    if doc.map.name != name:
        raise InvalidMapError(f"{source}: its name {doc.map.name!r} differs from the file name")
    values = {}
    for key in _PARAMS:
        try:
            value = doc.metadata.get(key)
            values[key] = validation.positive(key, value, where=f"{source} metadata")
        except InvalidConfigError as exc:
            raise InvalidMapError(str(exc)) from None
    if values["l_min"] > values["l_max"]:
        raise InvalidMapError(
            f"{source}: metadata l_min {values['l_min']} > l_max {values['l_max']}"
        )
    if not doc.description:
        raise InvalidMapError(f"{source}: missing its one-line description")
    return MapInfo(name=name, description=doc.description, map=doc.map, **values)


def builtin_info(name: str) -> MapInfo:
    """The built-in map ``name`` with its description and recommended parameters.

    Raises:
        UnknownNameError: naming ``name`` and the available maps.

    Examples:
        >>> info = builtin_info("corridor")
        >>> info.l_min, info.map.n_vertices
        (2.0, 8)
    """
    if not isinstance(name, str) or name not in _names():
        raise UnknownNameError(f"unknown built-in map {name!r}; available: {builtin_names()}")
    return _load(name)


def builtin_map(name: str) -> Map:
    """The built-in map ``name`` (see :func:`builtin_names`).

    Raises:
        UnknownNameError: naming ``name`` and the available maps.
    """
    return builtin_info(name).map
