"""One source for the env's arguments (EnvConfig) and a built-in map's parameters."""

from __future__ import annotations

import dataclasses
import inspect
import pickle
import warnings

import pytest

from envs import surveillance_v1
from envs.errors import InvalidConfigError, NarrowBandWarning, RhoAboveOneWarning
from envs.maps import builtin_info, builtin_map, builtin_names, save_map
from envs.surveillance.config import (
    GLOBAL_DEFAULTS,
    MAP_PARAMETERS,
    EnvConfig,
    env_parameters,
    map_recommendations,
)
from tests.envs.surveillance._worlds import open_room

FACTORIES = [surveillance_v1.parallel_env, surveillance_v1.raw_env, surveillance_v1.env]


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_every_factory_has_the_signature_of_envconfig(factory) -> None:
    params = inspect.signature(factory).parameters
    fields = dataclasses.fields(EnvConfig)
    assert list(params) == [f.name for f in fields]
    assert [p.default for p in params.values()] == [f.default for f in fields]
    assert env_parameters() == {f.name: f.default for f in fields}


@pytest.mark.parametrize("factory", FACTORIES, ids=lambda f: f.__name__)
def test_a_misspelt_option_is_a_type_error_with_a_suggestion(factory) -> None:
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'lmax'.*'l_max'\?"):
        factory(map=open_room(), lmax=3.0)
    with pytest.raises(TypeError, match="multiple values for argument 'map'"):
        factory(open_room(), map="corridor")


def test_positional_arguments_follow_the_field_order() -> None:
    env = surveillance_v1.parallel_env(open_room(), 1.0, 3.0)
    assert (env.config.l_min, env.config.l_max) == (1.0, 3.0)


@pytest.mark.parametrize("name", builtin_names())
def test_a_builtin_name_brings_its_recommended_parameters(name: str) -> None:
    info = builtin_info(name)
    cfg = surveillance_v1.parallel_env(map=name).config
    assert {k: getattr(cfg, k) for k in MAP_PARAMETERS} == info.params()


def test_every_builtin_recommends_the_global_defaults() -> None:
    """Changing a built-in's recommendation changes surveillance_v0 and v1 (STYLE.md 1: bump)."""
    for name in builtin_names():
        assert builtin_info(name).params() == GLOBAL_DEFAULTS, (
            f"{name} recommends {builtin_info(name).params()}: this changes what "
            f"surveillance_v1(map={name!r}) plays; add surveillance_v2 and update this test"
        )


def test_recommendations_follow_the_map_metadata(monkeypatch) -> None:
    """The env reads the map's metadata (not a copy of the defaults), explicit values win."""
    import envs.maps.builtin as builtin

    info = builtin_info("two_rooms")
    changed = dataclasses.replace(info, l_min=1.5, l_max=5.0, v_evader=0.25)
    monkeypatch.setattr(builtin, "builtin_info", lambda name: changed)
    cfg = EnvConfig(map="two_rooms")
    assert (cfg.l_min, cfg.l_max, cfg.v_pursuer, cfg.v_evader) == (1.5, 5.0, 1.0, 0.25)
    cfg = EnvConfig(map="two_rooms", l_max=3.0, v_evader=0.5)
    assert (cfg.l_min, cfg.l_max, cfg.v_evader) == (1.5, 3.0, 0.5)
    # a Map object or a file: the global defaults, whatever the map is called
    assert EnvConfig(map=builtin_map("two_rooms")).l_min == GLOBAL_DEFAULTS["l_min"]
    assert map_recommendations(builtin_map("two_rooms")) == GLOBAL_DEFAULTS


def test_a_map_file_brings_its_metadata_recommendations_as_a_built_in_does(tmp_path) -> None:
    """A file's metadata l_min / l_max / speeds were ignored (a user's 1.4 m room with
    l_min 0.2 was refused at L = 2, a larger one played at 2-4 against its own advice)."""
    path = tmp_path / "room.json"
    save_map(open_room(), path, metadata={"l_min": 1.0, "l_max": 2.0, "author": "anyone"})
    cfg = EnvConfig(map=str(path))
    assert (cfg.l_min, cfg.l_max, cfg.v_pursuer, cfg.v_evader, cfg.body_radius) == (
        1.0, 2.0, 1.0, 0.5, 0.1,
    )  # fmt: skip
    assert EnvConfig(map=path).l_min == 1.0  # a Path too
    assert map_recommendations(str(path)) == {**GLOBAL_DEFAULTS, "l_min": 1.0, "l_max": 2.0}
    cfg = EnvConfig(map=str(path), l_min=0.5, v_evader=0.25)  # explicit values win
    assert (cfg.l_min, cfg.l_max, cfg.v_evader) == (0.5, 2.0, 0.25)
    scaled = EnvConfig(map=f"{path}~x3rot0.5")  # scaled with the map, bodies included
    assert (scaled.l_min, scaled.l_max, scaled.v_pursuer) == (3.0, 6.0, 3.0)
    assert scaled.body_radius == pytest.approx(0.3)
    small = tmp_path / "small.json"
    save_map(open_room().transformed(((0.1, 0), (0, 0.1)), (0, 0), name="small"), small,
             metadata={"l_min": 0.2, "l_max": 0.4, "v_pursuer": 0.1, "v_evader": 0.05,
                       "body_radius": 0.01})  # fmt: skip
    cfg = EnvConfig(map=str(small))
    assert (cfg.l_min, cfg.body_radius, cfg.dt) == (0.2, 0.01, 0.1)
    surveillance_v1.parallel_env(map=str(small)).reset(seed=0)  # was refused at L = 2
    # nothing recommended (free-form keys and nulls, also transformed; a Map object): defaults
    plain = tmp_path / "plain.json"
    save_map(open_room(), plain, metadata={"author": "anyone", "l_min": None})
    for m in (str(plain), f"{plain}~x3", open_room()):
        cfg = EnvConfig(map=m)
        assert {k: getattr(cfg, k) for k in MAP_PARAMETERS} == GLOBAL_DEFAULTS
        assert cfg.body_radius == 0.1


@pytest.mark.parametrize(
    ("metadata", "message"),
    [
        ({"l_min": "2"}, r"room.json metadata: l_min = '2': expected a finite number > 0"),
        ({"v_evader": -1}, r"room.json metadata: v_evader = -1: expected a finite number > 0"),
        ({"l_max": True}, r"room.json metadata: l_max = True: expected a finite number > 0"),
        (
            {"l_min": 5},
            r"l_max = 4.0 \(the default; add it to the metadata\): expected a "
            r"value > l_min = 5",
        ),
        ({"l_min": 3, "l_max": 3}, r"metadata: l_max = 3: expected a value > l_min = 3$"),
        # was "--config: body_radius = 0.6: ..." from surveil play, without any --config
        ({"l_min": 1, "body_radius": 0.6}, r"body_radius = 0.6: expected a value in \(0, l_min"),
        ({"l_min": 0.15, "l_max": 1}, r"body_radius = 0.1 \(the default; add body_radius to "),
    ],
)
def test_a_map_file_s_bad_recommendation_is_one_line_naming_the_key(tmp_path, metadata, message):
    from envs.errors import InvalidMapError

    path = tmp_path / "room.json"
    save_map(open_room(), path, metadata=metadata)
    with pytest.raises(InvalidMapError, match=message):
        EnvConfig(map=str(path))


def test_pickling_replays_the_given_arguments() -> None:
    env = surveillance_v1.parallel_env(map="corridor", l_max=3.5, max_cycles=9)
    clone = pickle.loads(pickle.dumps(env))
    assert clone.config == env.config and clone.config.l_max == 3.5


def test_rho_above_one_is_legal_with_a_warning() -> None:
    with pytest.warns(RhoAboveOneWarning, match=r"v_evader = 1.5 > v_pursuer = 1.0") as record:
        env = surveillance_v1.parallel_env(map="open_room", v_evader=1.5)
    assert record[0].filename == __file__  # points at the caller, not at the env's internals
    env.reset(seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        surveillance_v1.parallel_env(map="open_room", v_evader=1.0)  # rho = 1: no warning


@pytest.mark.parametrize("make", [*FACTORIES, EnvConfig], ids=lambda f: f.__name__)
def test_a_band_narrower_than_two_evader_steps_is_legal_with_a_warning(make) -> None:
    """L_max - L_min < 2 V_e dt: within a step the evader moves V_e dt toward or away from
    the pursuer whatever it does, so one of the two distances is outside the band."""
    narrow = {"map": "open_room", "l_min": 2.0, "l_max": 2.15, "v_evader": 1.0}
    with pytest.warns(NarrowBandWarning, match=r"l_max - l_min = 0.15 < 2 v_evader dt = 0.2") as w:
        made = make(**narrow)
    assert len(w) == 1 and w[0].filename == __file__  # once, pointing at the caller
    assert "dt <= 0.075)" in str(w[0].message)  # the step that would do
    assert issubclass(NarrowBandWarning, UserWarning)
    if make is not EnvConfig:
        made.reset(seed=0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # exactly two steps wide, or a shorter step: no warning
        make(**{**narrow, "l_max": 2.2})
        make(**{**narrow, "dt": 0.05})
        warnings.simplefilter("ignore", NarrowBandWarning)  # filterable by its class
        make(**narrow)


@pytest.mark.parametrize(
    "refused",
    [
        {"max_cycles": 0},  # EnvConfig's own checks after the band's numbers
        {"body_radius": 1.5},  # >= l_min / 2
        {"dt": 1e4},  # the physics' check_step: a body would cross the map in one step
    ],
    ids=["max_cycles", "body_radius", "dt"],
)
@pytest.mark.parametrize(
    "unwinnable",
    [{"l_min": 2.0, "l_max": 2.15, "v_evader": 1.0}, {"v_evader": 1.5}],
    ids=["narrow_band", "rho_above_one"],
)
def test_a_config_about_to_be_refused_does_not_warn_first(refused, unwinnable) -> None:
    """A warning that the game is unwinnable came before the refusal of the same config
    (66d3fbf): ``surveil referee --config '{"dt": 1e4}'`` printed a warning line and then
    the error. The warnings are for configs the env builds; the refusal comes alone."""
    with warnings.catch_warnings(record=True) as shown:
        warnings.simplefilter("always")
        with pytest.raises(InvalidConfigError):
            surveillance_v1.parallel_env(map="open_room", **unwinnable, **refused)
    assert [str(w.message) for w in shown] == []


def test_the_env_card_shows_the_real_signature() -> None:
    """The signature block of the env card (surveillance_v1's docstring) agrees with the code."""
    card = surveillance_v1.__doc__
    block = card[card.index("surveillance_v1.parallel_env(") :]
    call = block[len("surveillance_v1.parallel_env") : block.index(")\n") + 1]
    shown = eval(f"dict{call}")  # the card writes plain literals
    assert shown == env_parameters()
