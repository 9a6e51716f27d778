"""Maps: the :class:`Map` world model, file formats, built-in worlds, random maps."""

from envs.maps.map import Feature, Map

__all__ = ["Feature", "Map"]
