"""draw_figure (`surveil figure NAME`) writes the parametric Figs. 11, 12 and 14."""

from __future__ import annotations

import pytest

from analysis.figures.evasion import FIGURES, draw_figure
from envs.errors import InvalidConfigError, SurveilValueError, UnknownNameError

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
