"""draw_figure (`surveil figure NAME`) writes the parametric Figs. 11, 12 and 14."""

from __future__ import annotations

import pytest

from analysis.figures.evasion import FIGURES, draw_arc, draw_figure
from envs.errors import InfeasibleError, InvalidConfigError, SurveilValueError, UnknownNameError
from strategies.control import shoot

pytest.importorskip("matplotlib")


@pytest.mark.parametrize("name", FIGURES)
def test_draw_figure_writes_png(name, tmp_path):
    out = draw_figure(name, tmp_path / f"{name}.png")
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_draw_figure_with_multipliers_and_errors(tmp_path):
    draw_figure("shooting", tmp_path / "s.png", lambda1=-1.0, lambda2_0=0.41, x_e=2.0)
    with pytest.raises(UnknownNameError, match="nope"):
        draw_figure("nope", tmp_path / "x.png")
    with pytest.raises(InvalidConfigError, match=r"unknown parameter\(s\) \['colour'\]"):
        draw_figure("tractrix", tmp_path / "x.png", colour="red")
    with pytest.raises(SurveilValueError, match="no optimal escape"):
        draw_figure(
            "shooting",
            tmp_path / "x.png",
            theta0=-1.4694468369271578,
            x_e=1.7090163413421233,
            L=1.1641292434617974,
            rho=0.8913647185839817,
            branch="-",
        )


def test_an_arc_unbounded_from_the_start_is_refused(tmp_path):
    # lambda1 = 1e300: H has no minimiser at x = 0, and the figure was drawn empty (exit 0)
    with pytest.raises(InfeasibleError, match=r"nothing to draw: H has no minimiser at the"):
        draw_figure("shooting", tmp_path / "x.png", lambda1=1e300)
    assert not (tmp_path / "x.png").exists()


def test_an_arc_unbounded_part_way_says_where_it_stops():
    # Fig. 11(b)'s multipliers at rho = 0.9 (REPRODUCTION.md: unbounded) stop at x = 0.51;
    # the title did not say why
    import matplotlib.pyplot as plt

    arc = shoot(0.5236, 1.0, 0.608, L=1.0, rho=0.9, x_max=2.0, stop_at_crossing=True)
    assert arc.unbounded and 1 < len(arc.x)
    fig, ax = plt.subplots()
    draw_arc(ax, arc, "shot")
    plt.close(fig)
    assert ax.get_title().endswith(f"from x = {arc.x[-1]:.4g}")
    assert "unbounded (H has no minimiser, THEORY §4.3)" in ax.get_title()


def test_tractrix_figure_refuses_a_leader_at_rest_or_overflowing(tmp_path):
    # v_e = 0 drew a single rod (t_max = 0, the same picture, was refused); v_e = t_max =
    # 1e300 overflowed to an empty figure with numpy's warnings
    with pytest.raises(InvalidConfigError, match=r"v_e = 0: expected > 0 \(a leader at rest"):
        draw_figure("tractrix", tmp_path / "x.png", v_e=0)
    with pytest.raises(SurveilValueError, match=r"v_e = 1e\+300 .* overflows"):
        draw_figure("tractrix", tmp_path / "x.png", v_e=1e300, t_max=1e300)
