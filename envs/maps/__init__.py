"""Maps: the :class:`Map` world model, file formats, built-in worlds, random maps."""

from envs.maps.builtin import MapInfo, builtin_info, builtin_map, builtin_names
from envs.maps.floor_plans import floor_plan
from envs.maps.io import MapDocument, load_map, read_map, save_map
from envs.maps.map import Feature, Map
from envs.maps.random_maps import random_map

__all__ = [
    "Feature",
    "Map",
    "MapDocument",
    "MapInfo",
    "builtin_info",
    "builtin_map",
    "builtin_names",
    "floor_plan",
    "load_map",
    "random_map",
    "read_map",
    "save_map",
]
