"""The exact decomposition against the grid oracle on worlds with slanted walls (issue 10).

The grid oracle (``tests/oracles/grid_oracle.py``) decides Sec. 4's verdict with no
critical curve: a grid of evader positions, the kernel's free arcs at each, arcs followed
along each grid step. Its error is one-sided: an evader win on the grid is a real escape,
a pursuer win may miss an escape through regions thinner than its spacing. So:

* where the grid's verdict is *resolution-stable* (the same at every spacing tried) and
  L is well away from the exact critical length, the exact verdict must be the grid's;
* where the grid finds an escape, the exact decomposition must find one too.

The tilted block has a vertex 2.647 above the floor; the exact verdict turns at
L = 2.64702..2.64703 (bisected). Closer to it the grid needs a fine spacing (measured with
8 neighbours): at L = 2.7 it says "pursuer wins" at 0.4, 0.3 and 0.25, at L = 2.8 it
finds the escape at 0.25 but not at 0.3 or 0.4. The trapezoid room at L = 4.5 shows the
same one-sided error: "pursuer wins" at 0.6 and 0.45 (8 neighbours), the escape found at
0.35 (4 neighbours) and 0.3 (4 and 8). Four neighbours keep the grid fast (1 to 2 s a
verdict).
"""

from __future__ import annotations

import pytest

from tests.oracles import grid_oracle as go
from tests.strategies.cspace._oracle import exact_decomposition, tilted_block
from tests.strategies.cspace.test_sweep_worlds import trapezoid_room

STABLE = [(tilted_block, 2.5), (tilted_block, 3.6)]


@pytest.mark.parametrize(("world", "L"), STABLE, ids=[f"{w.__name__}-L{L:g}" for w, L in STABLE])
def test_exact_verdict_is_the_grid_verdict_where_resolution_stable(world, L):
    m = world()
    grid = [go.grid_verdict(m, L, resolution=h, neighbourhood=4).evader_wins for h in (0.6, 0.45)]
    assert len(set(grid)) == 1, f"the grid's verdict depends on its spacing: {grid}"
    assert exact_decomposition(m, L).evader_wins == grid[0]


def test_a_grid_escape_is_an_exact_escape():
    m = trapezoid_room()
    assert go.grid_verdict(m, 4.5, resolution=0.35, neighbourhood=4).evader_wins
    assert exact_decomposition(m, 4.5).evader_wins
