"""Tournament specs: a TOML file (or a dict) validated on load, with errors naming the field.

A spec names the roster, the maps, a grid of env parameters, the start kind and the
seeds::

    name = "quick"                      # the run's name (default: the file's stem)
    description = "greedy vs baselines"
    maps = ["corridor", "two_rooms", "worlds/office.json", "random:7"]  # built-ins, files, seeds
    seeds = 10                          # seeds 0..9, or a list [3, 5, 8]
    start = "safe"                      # "safe", "valid", or a list of both
    time_limit = 120                    # seconds each role may spend deciding in a match
    salt = ""                           # mixed into every match identity (e.g. a code SHA)

    pursuers = ["pursuer/decomposition", "pursuer/greedy"]   # names, or tables:
    [[evaders]]
    policy = "evader/toward_away"       # a registered name ...
    params = { mode = "away" }          # ... with parameters
    label = "away"                      # how reports call it (default: the name)
    [[evaders]]
    model = "zoo:ppo_evader_vs_greedy_open_room"   # or a path to an SB3 model zip
    observation = { observation = "state" }        # default: from its provenance.json

    [env]                               # env overrides for every match
    max_cycles = 300
    [grid]                              # each combination is a variant
    rho = [0.3, 0.5]                    # v_evader = rho * v_pursuer
    l_max = [3.0, 4.0]
    [sprt]                              # optional: stop once "candidate vs baseline" is decided
    role = "pursuer"                    # whose roster both labels are in
    candidate = "pursuer/decomposition"
    baseline = "pursuer/greedy"
    p1 = 0.65                           # H1: P(candidate wins a discordant start) = p1 (H0: 0.5)
    alpha = 0.05                        # error rates of Wald's test
    beta = 0.05

``time_limit`` is a chess clock per role and per match: the seconds a role's policy may
spend in its ``reset`` and ``act`` calls (building the env, drawing the start and the
env's steps are on no clock). A role whose clock runs out forfeits the match; with no
policy deciding, a stretch of the env's or the harness's work longer than the limit (plus
a grace) is a hang: the match is an error, charged to nobody. The limit is part of each
match's identity (:mod:`analysis.tournament.identity`).

Every pairing on a map plays the same seeded starts (common random numbers): the start
depends only on the map, the env config and the seed. Relative paths are relative to
the spec file. Roster entries with the same identity (name, parameters, model file
content, observation) are merged with a warning; two different entries with one label
are an error.
"""

from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from analysis.arguments import why_not_a_file
from envs.errors import InvalidConfigError
from envs.validation import choice, integer, mapping, positive, string, unit_interval
from strategies.policies.model_files import (
    check_model_input,
    is_model_reference,
    model_path,
    warn_no_provenance,
)

__all__ = [
    "ENV_FIELDS",
    "MapEntry",
    "PolicyEntry",
    "Spec",
    "Variant",
    "load_spec",
    "spec_from_dict",
    "unseen_games",
]

ENV_FIELDS = (
    "l_min",
    "l_max",
    "v_pursuer",
    "v_evader",
    "dt",
    "max_cycles",
    "observation",
    "n_rays",
    "lidar_range",
    "reward",
    "body_radius",
    "spawn_margin_steps",
)
"""``EnvConfig`` fields a spec may set in ``[env]`` and ``[grid]`` (besides ``rho``)."""

_TOP = {
    "name",
    "description",
    "maps",
    "seeds",
    "start",
    "time_limit",
    "salt",
    "pursuers",
    "evaders",
    "env",
    "grid",
    "sprt",
}
_SPRT_KEYS = {"role", "candidate", "baseline", "p1", "alpha", "beta"}
_ENTRY_KEYS = {"policy", "params", "label", "model", "algo", "deterministic", "observation"}
_START_KINDS = ("safe", "valid")
DEFAULT_TIME_LIMIT = 300.0
MAX_SEED = 2**63 - 1
"""The largest seed a spec may list: the store keeps seeds as SQLite's 64-bit integers."""
TIME_LIMIT_RULE = "decision time per role"
"""What ``time_limit`` applies to, written into :meth:`Spec.to_dict` (so into the run's id):
a store's runs without it were played by an older surveil, whose limit counted the whole
match, the env's set-up included, and blamed the side that had spent more time deciding."""


@dataclass(frozen=True)
class PolicyEntry:
    """One roster entry.

    Attributes:
        role: ``"pursuer"`` or ``"evader"``.
        label: its name in reports (unique within the role).
        name: the registry name (``"pursuer/greedy"``), or ``"ROLE/sb3"`` for a model.
        params: ``make_policy`` parameters.
        model: the model file (absolute path) or ``None``.
        model_sha256: SHA-256 of the model file's bytes (its identity, not its path).
        observation: explicit observation options, or ``None`` (the policy's own).
    """

    role: str
    label: str
    name: str
    params: dict[str, Any] = field(default_factory=dict)
    model: str | None = None
    model_sha256: str | None = None
    observation: dict[str, Any] | None = None

    def identity(self) -> dict[str, Any]:
        """What decides this policy's play: name, parameters, model content, observation."""
        return {
            "name": self.name,
            "params": self.params,
            "model": self.model_sha256,
            "observation": self.observation,
        }


@dataclass(frozen=True)
class MapEntry:
    """One map: its label, where it came from, the Map and the recommended parameters (a
    built-in's or a map file's metadata; none for random maps)."""

    label: str
    source: str
    map: Any
    params: dict[str, float]

    @property
    def digest(self) -> str:
        """The map's geometry digest (its identity, not its path)."""
        return self.map.digest


@dataclass(frozen=True)
class Variant:
    """One combination of the grid: its label and env overrides (``rho`` kept apart)."""

    label: str
    overrides: dict[str, Any]
    rho: float | None = None


@dataclass(frozen=True)
class Spec:
    """A validated tournament spec (see the module docstring)."""

    name: str
    description: str
    source: str
    maps: tuple[MapEntry, ...]
    pursuers: tuple[PolicyEntry, ...]
    evaders: tuple[PolicyEntry, ...]
    seeds: tuple[int, ...]
    starts: tuple[str, ...]
    env: dict[str, Any]
    variants: tuple[Variant, ...]
    time_limit: float
    salt: str = ""
    sprt: dict[str, Any] | None = None

    def env_config(self, map_entry: MapEntry, variant: Variant) -> dict[str, Any]:
        """The resolved env parameters of a (map, variant): every field but the map.

        ``rho`` sets ``v_evader = rho * v_pursuer`` (the pursuer's speed as resolved).
        A rho above 1 or a range band narrower than two evader steps is legal here without
        a warning per match (see :func:`spec_from_dict`).
        """
        from envs.errors import NarrowBandWarning, RhoAboveOneWarning
        from envs.surveillance.config import EnvConfig
        from envs.surveillance.physics import check_step

        kwargs = {**map_entry.params, **self.env, **variant.overrides}
        where = f"{self.source} [env]" + (f" [grid] {variant.label}" if variant.label else "")
        where += f" on map {map_entry.label!r}"
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RhoAboveOneWarning)
                warnings.simplefilter("ignore", NarrowBandWarning)
                cfg = EnvConfig(map=map_entry.map, **kwargs)
                if variant.rho is not None:
                    kwargs["v_evader"] = variant.rho * cfg.v_pursuer
                    cfg = EnvConfig(map=map_entry.map, **kwargs)
            # what building the env would refuse, refused before any match (every match
            # was stored as an error and the run exited 0)
            check_step(cfg.map, cfg.dt, max(cfg.v_pursuer, cfg.v_evader), cfg.body_radius)
        except ValueError as exc:
            raise InvalidConfigError(f"{where}: {exc}") from exc
        d = cfg.to_dict()
        for k in ("map", "map_digest", "render_mode"):
            d.pop(k)
        return d

    def policies(self) -> dict[str, PolicyEntry]:
        """Every roster entry by ``"ROLE:label"``."""
        return {f"{p.role}:{p.label}": p for p in (*self.pursuers, *self.evaders)}

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready, normalised description (what identifies the run)."""
        return {
            "name": self.name,
            "description": self.description,
            "maps": [_map_dict(m) for m in self.maps],
            "pursuers": [_entry_dict(p) for p in self.pursuers],
            "evaders": [_entry_dict(p) for p in self.evaders],
            "seeds": list(self.seeds),
            "starts": list(self.starts),
            "env": self.env,
            "variants": [dataclasses.asdict(v) for v in self.variants],
            "time_limit": self.time_limit,
            "time_limit_rule": TIME_LIMIT_RULE,
            "salt": self.salt,
            **({"sprt": self.sprt} if self.sprt is not None else {}),
        }

    @property
    def run_id(self) -> str:
        """Content hash of the normalised spec: the same spec resumes the same run."""
        text = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def _map_dict(m: MapEntry) -> dict[str, Any]:
    d = {"label": m.label, "source": m.source, "digest": m.digest}
    if m.params and not m.source.startswith("builtin:"):
        # a file's recommendations (its metadata, not in the geometry digest) are part of
        # the run: editing them is a new run, not new matches added to the old one's rows
        d["params"] = m.params
    return d


def _entry_dict(p: PolicyEntry) -> dict[str, Any]:
    return {"role": p.role, "label": p.label, "model_path": p.model, **p.identity()}


def _default(name: str) -> Any:
    from envs.surveillance.config import env_parameters

    return env_parameters()[name]


# --------------------------------------------------------------------------- loading
def load_spec(path: str | os.PathLike[str]) -> Spec:
    """Read and validate a TOML spec.

    Raises:
        InvalidConfigError: naming the file, the field and what was expected.
    """
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib

    p = Path(path)
    problem = why_not_a_file(p)
    if problem is not None:
        raise InvalidConfigError(f"tournament spec {str(p)!r}: {problem}")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InvalidConfigError(f"{p}: not valid TOML ({exc})") from exc
    except RecursionError:  # the parser recurses once per nested array or table
        raise InvalidConfigError(f"{p}: not valid TOML (nested too deeply to read)") from None
    return spec_from_dict(data, source=str(p), base_dir=p.parent, default_name=p.stem)


def spec_from_dict(
    data: Mapping[str, Any],
    *,
    source: str = "<spec>",
    base_dir: str | os.PathLike[str] | None = None,
    default_name: str = "tournament",
    flags: Mapping[str, str] | None = None,
) -> Spec:
    """Validate a spec given as a dict (the parsed TOML); see :func:`load_spec`.

    ``flags`` names the command-line flag that gave a field (``{"maps": "--maps", "env":
    "--config"}``, as ``surveil evaluate`` builds its spec): a problem there is reported as
    ``--maps #2: ...`` instead of ``SOURCE [maps #2]: ...``.
    """
    flags = dict(flags or {})
    d = mapping("spec", data, where=source)
    unknown = sorted(set(d) - _TOP)
    if unknown:
        raise InvalidConfigError(f"{source}: unknown field(s) {unknown}; a spec has {sorted(_TOP)}")
    base = Path(base_dir) if base_dir is not None else Path.cwd()
    name = _printable("name", d.get("name", default_name), where=source)
    if name in (".", "..") or "/" in name or "\\" in name:  # it names files under out/
        raise InvalidConfigError(
            f"{source}: name = {name!r}: expected a plain name without '/' or '\\' (the "
            "default store is out/tournaments/NAME.sqlite); to store elsewhere pass --store"
        )
    description = string("description", d.get("description", ""), where=source, nonempty=False)
    for required in ("maps", "pursuers", "evaders"):
        if required not in d:
            raise InvalidConfigError(f"{source}: missing field {required!r}")
    maps = _maps(d["maps"], source, base, flags.get("maps"))
    pursuers = _roster(d["pursuers"], "pursuer", source, base, flags.get("pursuers"))
    evaders = _roster(d["evaders"], "evader", source, base, flags.get("evaders"))
    starts = _starts(d.get("start", "safe"), source)
    env = _env_table(d.get("env", {}), flags.get("env", f"{source} [env]"))
    variants = _grid(d.get("grid", {}), f"{source} [grid]")
    if "v_evader" in env and any(v.rho is not None for v in variants):
        # rho sets v_evader = rho * v_pursuer: the [env] value was dropped without a word
        raise InvalidConfigError(
            f"{flags.get('env', f'{source} [env]')}: v_evader = {env['v_evader']!r} and "
            f"{source} [grid] rho both set the evader's speed (rho sets v_evader = rho * "
            "v_pursuer); give one"
        )
    per_seed = len(maps) * len(variants) * len(starts) * len(pursuers) * len(evaders)
    seeds = _seeds(d.get("seeds", 10), source, per_seed)
    time_limit = positive("time_limit", d.get("time_limit", DEFAULT_TIME_LIMIT), where=source)
    salt = string("salt", d.get("salt", ""), where=source, nonempty=False)
    sprt = None
    if "sprt" in d:
        sprt = _sprt(d["sprt"], f"{source} [sprt]", {"pursuer": pursuers, "evader": evaders})
    spec = Spec(
        name=name,
        description=description,
        source=source,
        maps=maps,
        pursuers=pursuers,
        evaders=evaders,
        seeds=seeds,
        starts=starts,
        env=env,
        variants=variants,
        time_limit=time_limit,
        salt=salt,
        sprt=sprt,
    )
    seen: dict[str, str] = {}
    fast: list[str] = []
    narrow: list[str] = []  # bands narrower than two evader steps
    every: list[dict[str, Any]] = []  # the env config of each (map, variant)
    for m in spec.maps:  # every (map, variant) must make a valid env config
        configs = [spec.env_config(m, v) for v in spec.variants]
        every += configs
        fast += [
            f"{m.label} {v.label}".strip()
            for v, c in zip(spec.variants, configs, strict=True)
            if c["v_evader"] > c["v_pursuer"]
        ]
        narrow += [
            f"{m.label} {v.label}".strip()
            for v, c in zip(spec.variants, configs, strict=True)
            if c["l_max"] - c["l_min"] < 2.0 * c["v_evader"] * c["dt"] * (1.0 - 1e-9)
        ]
        games = json.dumps(configs, sort_keys=True)
        key = m.digest + games
        if key in seen:
            raise InvalidConfigError(
                f"{source}: maps {seen[key]!r} and {m.label!r} are the same world with the "
                f"same parameters (digest {m.digest[:12]}); list it once"
            )
        seen[key] = m.label
    for role, flag in (("pursuer", flags.get("pursuers")), ("evader", flags.get("evaders"))):
        for entry in getattr(spec, f"{role}s"):
            _check_model_input(entry, every, flag or f"{source} [{role}s]")
    if fast:
        from envs.errors import RhoAboveOneWarning

        warnings.warn(
            f"{source}: rho > 1 in {fast}: the evader can always escape there (Sec. 5)",
            RhoAboveOneWarning,
            stacklevel=2,
        )
    if narrow:
        from envs.errors import NarrowBandWarning

        warnings.warn(
            f"{source}: l_max - l_min < 2 v_evader dt in {narrow}: within a step the evader "
            "can move v_evader dt toward or away from the pursuer whatever it does, so no "
            "pursuer can be sure to hold the range band there (a wider band or a shorter dt)",
            NarrowBandWarning,
            stacklevel=2,
        )
    return spec


def _check_model_input(entry: PolicyEntry, games: list[dict[str, Any]], where: str) -> None:
    """Refuse a model ``entry`` whose zip takes observations of another shape than the
    ones the spec's games (env configs) give it: it failed its first act() in every match,
    each a forfeit (a model without its provenance.json is given the env's observation).

    Raises:
        InvalidConfigError: naming the entry, the model's input shape and the one given.
    """
    if entry.model is None or "inputs" in entry.params:
        return  # a model of analytic features builds its input from the state itself
    opts = entry.observation or {}
    check_model_input(
        Path(entry.model),
        ({k: opts.get(k, game[k]) for k in ("observation", "n_rays")} for game in games),
        f"{where}: {entry.label!r}",
        given_by="its entry's" if "observation" in opts else "the spec's env",
        then="every match would be a forfeit; give the entry the observation it was "
        "trained on (observation = { observation = ..., n_rays = ... }), or put the "
        "provenance.json its training wrote beside it",
    )


def _sprt(value: Any, where: str, rosters: Mapping[str, tuple[PolicyEntry, ...]]) -> dict:
    d = mapping("sprt", value, where=where)
    unknown = sorted(set(d) - _SPRT_KEYS)
    if unknown:
        raise InvalidConfigError(
            f"{where}: unknown field(s) {unknown}; [sprt] has {sorted(_SPRT_KEYS)}"
        )
    for required in ("role", "candidate", "baseline"):
        if required not in d:
            raise InvalidConfigError(f"{where}: missing field {required!r}")
    role = choice("role", d["role"], ("pursuer", "evader"), where=where)
    labels = [p.label for p in rosters[role]]
    out: dict[str, Any] = {"role": role}
    for key in ("candidate", "baseline"):
        label = string(key, d[key], where=where)
        if label not in labels:
            raise InvalidConfigError(
                f"{where}: {key} = {label!r}: expected a label of the {role} roster {labels}"
            )
        out[key] = label
    if out["candidate"] == out["baseline"]:
        raise InvalidConfigError(f"{where}: candidate and baseline are both {out['candidate']!r}")
    for key, default in (("p1", 0.65), ("alpha", 0.05), ("beta", 0.05)):
        out[key] = unit_interval(key, d.get(key, default), where=where)
    if out["p1"] <= 0.5:
        raise InvalidConfigError(f"{where}: p1 = {out['p1']!r}: expected a number in (0.5, 1)")
    return out


def _list(name: str, value: Any, where: str) -> list[Any]:
    if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)):
        value = [value]
    if not value:
        raise InvalidConfigError(f"{where}: {name} = []: expected at least one entry")
    return list(value)


def _map_entry(text: str, where: str, base: Path) -> MapEntry:
    """A built-in name, ``random:...``, a file relative to ``base``, or any of these
    followed by ``~[xS][rotR][off(X,Y)]`` (:func:`envs.maps.io.split_transform`)."""
    from envs.maps import builtin_info, builtin_names, load_map
    from envs.maps.io import recommended_parameters, scaled_parameters, split_transform

    if text in builtin_names():
        info = builtin_info(text)
        return MapEntry(text, f"builtin:{text}", info.map, dict(info.params()))
    if text.startswith("random:") and "~" not in text:  # a seeded random map, by its seed
        try:
            return MapEntry(text, text, load_map(text), {})
        except ValueError as exc:
            raise InvalidConfigError(f"{where}: {exc}") from exc
    path = (base / text).resolve()
    if not path.is_file():
        try:
            name, sim = split_transform(text)
        except ValueError as exc:
            raise InvalidConfigError(f"{where}: {exc}") from exc
        if sim is not None:  # the map it transforms, then the similarity
            inner = _map_entry(name, where, base)
            try:
                world = inner.map.transformed(sim.matrix, sim.offset, name=text)
            except ValueError as exc:
                raise InvalidConfigError(
                    f"{where}: map = {text!r}: {name!r} under that transform is no valid map: {exc}"
                ) from exc
            # a transformed built-in's or file's recommendation, bodies included, as
            # EnvConfig reads the name (random maps and files recommending nothing: none)
            params = scaled_parameters(inner.params, sim.scale) if inner.params else {}
            return MapEntry(text, f"{inner.source}~{sim.label()}", world, params)
        raise InvalidConfigError(
            f"{where}: map = {text!r}: neither a built-in map {builtin_names()}, "
            f"'random:[KIND:]SEED', nor a map file (looked for {path}), nor one of these "
            "followed by '~[xS][rotR][off(X,Y)]'"
        )
    try:
        world = load_map(path)
        params = recommended_parameters(path) or {}  # the file's metadata, as EnvConfig reads it
    except (ValueError, OSError) as exc:
        raise InvalidConfigError(f"{where}: map = {text!r}: {exc}") from exc
    return MapEntry(text, str(path), world, params)


def _maps(value: Any, source: str, base: Path, flag: str | None = None) -> tuple[MapEntry, ...]:
    out: dict[str, MapEntry] = {}
    for i, item in enumerate(_list("maps", value, source)):
        where = f"{flag} #{i + 1}" if flag else f"{source} [maps #{i + 1}]"
        text = string("map", item, where=where)
        entry = _map_entry(text, where, base)
        if entry.label in out:
            warnings.warn(f"{where}: map {text!r} is listed twice; playing it once", stacklevel=3)
            continue
        out[entry.label] = entry
    return tuple(out.values())


def _roster(
    value: Any, role: str, source: str, base: Path, flag: str | None = None
) -> tuple[PolicyEntry, ...]:
    section = f"{role}s"
    entries: list[PolicyEntry] = []
    for i, item in enumerate(_list(section, value, source)):
        where = f"{flag} #{i + 1}" if flag else f"{source} [{section} #{i + 1}]"
        entries.append(_entry(item, role, where, base))
    merged: dict[str, PolicyEntry] = {}
    by_identity: dict[str, str] = {}
    for e in entries:
        ident = json.dumps(e.identity(), sort_keys=True)
        if ident in by_identity:
            warnings.warn(
                f"{flag or f'{source} [{section}]'}: {e.label!r} repeats "
                f"{by_identity[ident]!r} (same "
                "policy, parameters and model); merged into one entry",
                stacklevel=3,
            )
            continue
        if e.label in merged:
            raise InvalidConfigError(
                f"{source} [{section}]: two different entries are labelled {e.label!r}; "
                "give them distinct labels"
            )
        by_identity[ident] = e.label
        merged[e.label] = e
    return tuple(merged.values())


def _roster_item(item: str, role: str) -> str | dict[str, str]:
    """A roster item given as one string, as a spec entry: ``zoo:NAME``, ``*.zip`` and
    ``ROLE/sb3:PATH`` (the registry's name, surveil policies) are learned models
    (``{"model": ...}``: the file's content is then part of each match's identity),
    anything else a registered policy name."""
    if item.startswith(f"{role}/sb3:"):
        return {"model": item.removeprefix(f"{role}/sb3:")}
    if item.startswith(("pursuer/sb3:", "evader/sb3:")):
        return item  # the other role's: refused as a name of the wrong role
    if is_model_reference(item):
        return {"model": item}
    return item


def _entry(item: Any, role: str, where: str, base: Path) -> PolicyEntry:
    from strategies.policies import make_policy

    if isinstance(item, str):
        item = _roster_item(item, role)
        if isinstance(item, str):
            item = {"policy": item}
    d = mapping("entry", item, where=where)
    unknown = sorted(set(d) - _ENTRY_KEYS)
    if unknown:
        raise InvalidConfigError(
            f"{where}: unknown field(s) {unknown}; expected {sorted(_ENTRY_KEYS)}"
        )
    if ("policy" in d) == ("model" in d):
        raise InvalidConfigError(
            f"{where}: give exactly one of 'policy' (a name) or 'model' (a file)"
        )
    if "model" in d and "params" in d:
        raise InvalidConfigError(
            f"{where}: 'params' applies to 'policy' entries only; a 'model' entry takes "
            "'algo' and 'deterministic'"
        )
    if "policy" in d and isinstance(d["policy"], str) and d["policy"].startswith(f"{role}/sb3:"):
        model = d["policy"].removeprefix(f"{role}/sb3:")
        raise InvalidConfigError(
            f"{where}: policy = {d['policy']!r} names a model file: write model = {model!r} "
            "(its content is then part of each match's identity)"
        )
    observation = None
    if "observation" in d:
        from strategies.runner import check_observation_options

        observation = check_observation_options(d["observation"], f"{where} observation")
    if "policy" in d:
        name = string("policy", d["policy"], where=where)
        if name.partition("/")[0] != role:
            raise InvalidConfigError(
                f"{where}: policy = {name!r}: {'an' if role == 'evader' else 'a'} {role} entry "
                f"needs a name '{role}/KIND'"
            )
        for k in ("algo", "deterministic"):
            if k in d:
                raise InvalidConfigError(f"{where}: {k!r} applies to 'model' entries only")
        params = mapping("params", d.get("params", {}), where=where)
        try:
            policy = make_policy(name, **params)  # the name and parameters are checked here
        except ValueError as exc:
            raise InvalidConfigError(f"{where}: {exc}") from exc
        kind = (observation or {}).get("observation", "state")
        if policy.uses_state and kind != "state":  # each of its matches was an error
            raise InvalidConfigError(
                f"{where}: policy {name!r} reads the state, so it cannot be given "
                f"observation = {observation!r}; drop the entry's observation (an "
                "observation is for a policy that reads the env's, such as a model)"
            )
        label = _printable("label", d.get("label", name), where=where)
        params = _without_defaults(name, params)
        return PolicyEntry(role, label, name, _canonical(params), None, None, observation)
    text = string("model", d["model"], where=where)
    path = model_file(text, where, base)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    provenance = _provenance(path)
    if not (path.parent / "provenance.json").is_file():
        warn_no_provenance(f"{where}: model = {text!r}", path)
    if provenance.get("role") not in (None, role):
        raise InvalidConfigError(
            f"{where}: model {text!r} was trained as the {provenance['role']}, not the {role}"
        )
    params: dict[str, Any] = {}
    algo = d.get("algo", provenance.get("algo"))
    if algo is not None:
        from strategies.policies.learned import check_algo

        try:
            params["algo"] = check_algo(string("algo", algo, where=where), path)
        except InvalidConfigError as exc:  # each match of the entry was an error
            raise InvalidConfigError(f"{where}: model = {text!r}: {exc}") from None
    if "deterministic" in d:
        from envs.validation import boolean

        params["deterministic"] = boolean("deterministic", d["deterministic"], where=where)
    from strategies.policies.learned import learner_inputs_spec

    inputs = learner_inputs_spec(provenance)
    if inputs is not None:
        # trained with analytic features: it reads the state and builds its input itself
        # (the copy of the zip a worker loads has no provenance beside it)
        params["inputs"] = _canonical(inputs)
        if observation is not None and observation.get("observation") != "state":
            raise InvalidConfigError(
                f"{where}: model {text!r} computes analytic features {inputs['features']} "
                f"from the state; it cannot be given observation {observation!r}"
            )
        observation = {"observation": "state"}
    if observation is None:
        env_cfg = provenance.get("env_config") or {}
        if isinstance(env_cfg, Mapping) and env_cfg.get("observation"):
            observation = {"observation": env_cfg["observation"]}
            if env_cfg["observation"] != "state":
                observation["n_rays"] = env_cfg.get("n_rays", _default("n_rays"))
                observation["lidar_range"] = env_cfg.get("lidar_range")
    label = _printable("label", d.get("label", text), where=where)
    return PolicyEntry(role, label, f"{role}/sb3", params, str(path), digest, observation)


def _printable(key: str, value: Any, *, where: str) -> str:
    """A label or name: a non-empty string on one line of printable characters. A label
    with a line break split the report's Markdown table rows and the terminal table."""
    text = string(key, value, where=where)
    if not text.isprintable():
        raise InvalidConfigError(
            f"{where}: {key} = {text!r}: expected one line of printable text (no line "
            "breaks, tabs or control characters: it heads rows and columns of the report)"
        )
    return text


def _without_defaults(name: str, params: Mapping[str, Any]) -> dict[str, Any]:
    """``params`` less those given at the policy's default value: the same policy plays
    either way, so both spellings have one identity (a spec that wrote ``{"gain": 1.0}``
    at the default is the same entry, and the same matches, as one that left it out)."""
    from strategies.policies.registry import policy_spec

    defaults = policy_spec(name).params
    return {k: v for k, v in params.items() if not (k in defaults and _same(v, defaults[k]))}


def _same(value: Any, default: Any) -> bool:
    # 1 and 1.0 are one value to a policy; True is not 1 (make_policy refuses it there)
    return isinstance(value, bool) == isinstance(default, bool) and value == default


def _canonical(params: Mapping[str, Any]) -> dict[str, Any]:
    return json.loads(json.dumps(dict(params), sort_keys=True))


def model_file(text: str, where: str, base: Path | None = None) -> Path:
    """The model file ``text`` names: ``zoo:NAME`` (a shipped model) or a path (relative
    to ``base``, default the current directory), checked to be an SB3 model zip.

    Raises:
        InvalidConfigError: no such zoo model (listing them) or file, or not a model zip;
            the message starts with ``where``.
    """
    return model_path(text, f"{where}: model = {text!r}", base)


def _provenance(model: Path) -> dict[str, Any]:
    prov = model.parent / "provenance.json"
    try:
        data = json.loads(prov.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def unseen_games(spec: Spec) -> list[tuple[type[Warning], str]]:
    """The warnings a learned model of ``spec`` earns, one of each kind per model: it
    plays games its provenance says it was not trained at
    (:class:`~strategies.policies.learned.UnseenParametersWarning`, each difference with
    the maps and variants where it holds unless it holds on all), or, seeing map
    coordinates, maps it has not seen (:class:`~strategies.policies.learned.UnseenMapWarning`).

    The driver says them once per run in the main process: the copy of a model's file a
    worker plays has no provenance beside it (it said nothing), and a worker would say
    them once per process and game.
    """
    from strategies.policies.learned import (
        UnseenMapWarning,
        UnseenParametersWarning,
        maps_trained_on,
        trained_map_digests,
        unseen_map_message,
        unseen_parameters,
        unseen_parameters_message,
    )

    games = [
        (m.label + (f" [{v.label}]" if v.label else ""), spec.env_config(m, v))
        for m in spec.maps
        for v in spec.variants
    ]
    out: list[tuple[type[Warning], str]] = []
    for entry in (*spec.pursuers, *spec.evaders):
        if entry.model is None:
            continue
        provenance = _provenance(Path(entry.model))
        differ: dict[str, list[str]] = {}
        for where, game in games:
            key = unseen_parameters(provenance, game)
            if key is not None:
                differ.setdefault(key, []).append(where)
        if differ:
            everywhere = len(differ) == 1 and len(next(iter(differ.values()))) == len(games)
            text = " | ".join(
                key if everywhere else f"{key} (on {', '.join(where)})"
                for key, where in differ.items()
            )
            message = unseen_parameters_message(entry.label, text, games=len(differ))
            out.append((UnseenParametersWarning, message))
        trained = maps_trained_on(provenance)
        if trained:
            known = trained_map_digests(provenance)
            unseen = [m.label for m in spec.maps if m.map.digest not in known]
            if unseen:
                message = unseen_map_message(entry.label, trained, unseen)
                out.append((UnseenMapWarning, message))
    return out


_BYTES_PER_MATCH = 2100.0
"""Peak memory of one planned match in the driver (its identity, the plan's lists, the
store's registration): 1,987-2,084 bytes measured (``ru_maxrss`` above the start, 2e4 and
1e5 matches, ``/work/scratch/s12/helper-75/plan_mem.py``)."""


def _seeds(value: Any, source: str, per_seed: int = 1) -> tuple[int, ...]:
    """The seeds, after checking that the plan of ``per_seed`` matches a seed fits in the
    memory budget (``seeds = 1e9`` built a tuple of a billion seeds: a MemoryError
    traceback, or the OOM killer, before any check).

    Raises:
        InvalidConfigError: a bad seed (one beyond :data:`MAX_SEED`, which the store's
            64-bit integers cannot hold, was an ``OverflowError`` traceback once the
            store was open), none, or a repeated one.
        MemoryBudgetError: too many matches to plan (naming how many seeds fit).
    """
    if isinstance(value, (list, tuple)):
        seeds = [
            integer(f"seeds[{i}]", s, minimum=0, maximum=MAX_SEED, where=source)
            for i, s in enumerate(value)
        ]
        if not seeds:
            raise InvalidConfigError(f"{source}: seeds = []: expected at least one seed")
        if len(set(seeds)) != len(seeds):
            raise InvalidConfigError(f"{source}: seeds = {seeds}: a seed is repeated")
        _check_plan(len(seeds), per_seed, source)
        return tuple(seeds)
    n = integer("seeds", value, minimum=1, where=source)
    _check_plan(n, per_seed, source)
    return tuple(range(n))


def _check_plan(n: int, per_seed: int, source: str) -> None:
    from envs.errors import MemoryBudgetError
    from strategies.memory import memory_budget

    limit = memory_budget()
    need = _BYTES_PER_MATCH * n * per_seed
    if need <= limit:
        return
    fit = int(limit // (_BYTES_PER_MATCH * per_seed))
    raise MemoryBudgetError(
        f"{source}: seeds = {n:,} make {n * per_seed:,} matches ({per_seed:,} a seed: maps x "
        f"grid x starts x pursuers x evaders), about {need / 1e9:.3g} GB to plan, more than "
        f"the memory budget of {limit / 1e9:.3g} GB; expected {MemoryBudgetError.KNOB} <= "
        f"{fit:,}, or raise the budget with {MemoryBudgetError.BUDGET}",
        "seeds",
        budget=MemoryBudgetError.ENV_BUDGET,  # a spec has no memory_budget argument
        size=f"{max(1, round(1.2 * need / 1e9))}GB",
    )


def _starts(value: Any, source: str) -> tuple[str, ...]:
    kinds = [choice("start", s, _START_KINDS, where=source) for s in _list("start", value, source)]
    return tuple(dict.fromkeys(kinds))


def _env_value(key: str, value: Any, where: str) -> Any:
    if key == "observation":
        return choice(key, value, ("state", "lidar"), where=where)
    if key == "reward":
        return choice(key, value, ("zero_sum", "sparse"), where=where)
    if key in ("max_cycles", "n_rays"):
        return integer(key, value, minimum=1, where=where)
    if key == "spawn_margin_steps":
        return integer(key, value, minimum=0, where=where)
    if key == "lidar_range" and value is None:
        return None
    return positive(key, value, where=where)


def _env_table(value: Any, where: str) -> dict[str, Any]:
    d = mapping("env", value, where=where)
    unknown = sorted(set(d) - set(ENV_FIELDS))
    if unknown:
        raise InvalidConfigError(
            f"{where}: unknown env parameter(s) {unknown}; expected {list(ENV_FIELDS)}"
        )
    return {k: _env_value(k, v, where) for k, v in d.items()}


def _grid(value: Any, where: str) -> tuple[Variant, ...]:
    d = mapping("grid", value, where=where)
    allowed = (*ENV_FIELDS, "rho")
    unknown = sorted(set(d) - set(allowed))
    if unknown:
        raise InvalidConfigError(
            f"{where}: unknown grid parameter(s) {unknown}; expected {list(allowed)}"
        )
    if "rho" in d and "v_evader" in d:
        raise InvalidConfigError(f"{where}: give 'rho' or 'v_evader', not both")
    axes = []
    for k, v in d.items():
        values = [_env_value(k, x, where) for x in _list(k, v, where)]
        if len(set(map(repr, values))) != len(values):
            raise InvalidConfigError(f"{where}: {k} = {values}: a value is repeated")
        axes.append([(k, x) for x in values])
    if not axes:
        return (Variant("", {}),)
    out = []
    for combo in itertools.product(*axes):
        overrides = {k: v for k, v in combo if k != "rho"}
        rho = next((v for k, v in combo if k == "rho"), None)
        label = ",".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in combo)
        out.append(Variant(label, overrides, rho))
    return tuple(out)
