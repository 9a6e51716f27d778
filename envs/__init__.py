"""The world: maps, geometry kernel, pymunk physics, the PettingZoo env and rendering.

Nothing in this package knows that a policy exists (see ``DESIGN.md``).
"""
