"""Exact intersections and tangencies of critical-curve pieces, vectorised over pairs.

* segment-segment, segment-arc and arc-arc: closed forms; a line and a circle (or two
  circles) closer than ``touch`` without crossing *touch* at one point (the foot of the
  perpendicular, the point between the circles), so an exact tangency (a type-1 line
  ending on the type-2 arc it is tangent to) gives one point whatever the rounding;
* anything with a conchoid: the conchoid is sampled (uniformly in its tip parameter and
  in its rod angle, which resolves both its ends and its apex) and the other curve's
  implicit function is followed along it; sign changes are bisected to double precision,
  and so are the zeros of its derivative between samples of one sign (local extrema):
  an extremum that crosses zero brackets two roots, one closer than ``touch`` to zero is
  a tangency. When the other curve is a conchoid too, its implicit function is angular
  about its vertex (the curve passes through the vertex along two lines, see
  :func:`refine_about`): the samples are refined there until each interval turns by
  less than the angle between those lines, so no two roots share an interval.

Each routine returns flat arrays ``(pair, tA, tB)``: pair index, the parameter on the
first curve and on the second (unclamped: the caller checks them against the pieces'
parameter ranges).
"""

from __future__ import annotations

import numpy as np

from strategies.cspace._shapes import derivatives, gradient, implicit, points

__all__ = [
    "arc_arc",
    "conchoid_samples",
    "node_sweep",
    "refine_about",
    "sampled_roots",
    "seg_arc",
    "seg_seg",
]

_PARALLEL = 1e-12  # |sin| of the angle below which two segments are parallel
_BISECT = 64  # halvings of a bracket: below double precision on any interval
_MAX_SWEEP = np.pi / 8  # largest turn about a conchoid's vertex of one sample interval
_MIN_SWEEP = np.pi / 256  # ... even when the conchoid's two lines there nearly coincide
_REFINE = 48  # halvings of a sample interval, at most


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def seg_seg(oa, da, ob, db):
    """Crossings of lines ``oa + t da`` and ``ob + s db`` (unit directions), (k,) pairs.

    Returns:
        ``(pair, ta, tb)`` for the non-parallel pairs.
    """
    den = _cross(da, db)
    ok = np.abs(den) > _PARALLEL
    r = ob - oa
    with np.errstate(divide="ignore", invalid="ignore"):
        ta = _cross(r, db) / den
        tb = _cross(r, da) / den
    idx = np.flatnonzero(ok)
    return idx, ta[idx], tb[idx]


def seg_arc(o, d, c, R, touch: float):
    """Points of line ``o + t d`` on circle ``|x - c| = R``: ``(pair, t, psi)``."""
    f = c - o
    tf = (f * d).sum(axis=1)  # foot of the perpendicular from c
    h = np.abs(_cross(d, f))  # distance from c to the line
    tangent = np.abs(h - R) <= touch
    cross = ~tangent & (h < R)
    s = np.sqrt(np.where(cross, R * R - h * h, 0.0))
    pair = np.concatenate([np.flatnonzero(tangent), np.flatnonzero(cross), np.flatnonzero(cross)])
    t = np.concatenate([tf[tangent], (tf - s)[cross], (tf + s)[cross]])
    x = o[pair] + t[:, None] * d[pair]
    rel = x - c[pair]
    psi = np.arctan2(rel[:, 1], rel[:, 0])
    return pair, t, psi


def arc_arc(c1, R1, c2, R2, touch: float, same: float):
    """Points on both circles ``|x - c1| = R1`` and ``|x - c2| = R2``: ``(pair, psi1, psi2)``.

    Circles with centres closer than ``same`` are skipped (one vertex: one circle).
    """
    e = c2 - c1
    D = np.hypot(e[:, 0], e[:, 1])
    ok = D > same
    with np.errstate(divide="ignore", invalid="ignore"):
        eu = e / D[:, None]
    outer = ok & (np.abs(D - (R1 + R2)) <= touch)
    inner = ok & ~outer & (np.abs(D - np.abs(R1 - R2)) <= touch)
    cross = ok & ~outer & ~inner & (D < R1 + R2) & (D > np.abs(R1 - R2))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (D * D + R1 * R1 - R2 * R2) / (2.0 * D)
    hh = np.sqrt(np.where(cross, np.maximum(R1 * R1 - a * a, 0.0), 0.0))
    perp = np.stack([-eu[:, 1], eu[:, 0]], axis=1)
    sign_in = np.where(R1 >= R2, 1.0, -1.0)
    pair = np.concatenate(
        [np.flatnonzero(outer), np.flatnonzero(inner), np.flatnonzero(cross), np.flatnonzero(cross)]
    )
    base = (
        c1[pair]
        + eu[pair] * np.concatenate([R1[outer], (sign_in * R1)[inner], a[cross], a[cross]])[:, None]
    )
    off = np.concatenate([np.zeros(outer.sum() + inner.sum()), hh[cross], -hh[cross]])
    x = base + off[:, None] * perp[pair]
    r1 = x - c1[pair]
    r2 = x - c2[pair]
    return pair, np.arctan2(r1[:, 1], r1[:, 0]), np.arctan2(r2[:, 1], r2[:, 0])


def conchoid_samples(data: np.ndarray, lo: np.ndarray, hi: np.ndarray, n: int):
    """Sample parameters of conchoid pieces: ``n`` uniform in the tip parameter ``s`` and
    ``n`` uniform in the rod angle ``phi`` (``s = c + h tan phi``), merged and sorted.

    Returns:
        ``(owner, t)`` flat arrays, sorted by owner then parameter.
    """
    k = len(lo)
    if k == 0:
        return np.zeros(0, dtype=np.intp), np.zeros(0)
    v, a, u = data[:, 0:2], data[:, 2:4], data[:, 4:6]
    nrm = np.stack([-u[:, 1], u[:, 0]], axis=1)
    c = ((v - a) * u).sum(axis=1)
    h = np.abs(((v - a) * nrm).sum(axis=1))
    j = np.arange(n + 1) / n
    s_uni = lo[:, None] + (hi - lo)[:, None] * j
    p0 = np.arctan2(lo - c, h)
    p1 = np.arctan2(hi - c, h)
    s_phi = c[:, None] + h[:, None] * np.tan(p0[:, None] + (p1 - p0)[:, None] * j)
    s_phi = np.clip(s_phi, lo[:, None], hi[:, None])
    t = np.concatenate([s_uni, s_phi[:, 1:-1]], axis=1)
    t.sort(axis=1)
    owner = np.repeat(np.arange(k), t.shape[1])
    return owner, t.ravel()


def node_sweep(data: np.ndarray, L: float) -> np.ndarray:
    """Per conchoid ``(v, a, u)``: the largest turn about ``v`` a sample interval may make.

    Near its vertex ``v`` a conchoid's implicit function (:mod:`strategies.cspace._shapes`)
    has the sign of ``h - L |cos alpha|`` (``h``: the height of ``v`` above the edge's
    line, ``alpha``: the direction from ``v``, measured from the edge's normal): it
    changes sign on the two lines through ``v`` at ``cos alpha = +-h / L``, whatever the
    distance to ``v``. A curve passing close to ``v`` crosses both within a short stretch;
    an interval turning by less than half the angle between neighbouring rays of those
    lines (``2 phi0`` and ``pi - 2 phi0``, ``cos phi0 = h / L``) holds at most one of
    those crossings.
    """
    v, a, u = data[:, 0:2], data[:, 2:4], data[:, 4:6]
    h = np.abs(u[:, 0] * (v[:, 1] - a[:, 1]) - u[:, 1] * (v[:, 0] - a[:, 0]))
    phi0 = np.arccos(np.clip(h / L, 0.0, 1.0))
    return np.clip(0.5 * np.minimum(2.0 * phi0, np.pi - 2.0 * phi0), _MIN_SWEEP, _MAX_SWEEP)


def refine_about(kind_a, data_a, owner, t, centre, sweep, L: float, floor: float):
    """Samples of curves A refined until each interval turns by at most ``sweep`` about
    ``centre`` (per pair: the vertex of the conchoid whose implicit function is followed
    along A, see :func:`node_sweep`).

    An interval is halved while the directions from ``centre`` to its two ends differ by
    more than ``sweep`` and both ends are farther than ``floor`` from ``centre`` (closer,
    they are ``centre``: a vertex). Only intervals near ``centre`` are split: far from it,
    the sampling already turns little.

    Args:
        kind_a, data_a: per pair, the sampled curve A.
        owner, t: samples as for :func:`sampled_roots` (sorted by pair, then parameter).
        centre: (k, 2) per pair, the point to resolve (``nan``: none).
        sweep: (k,) per pair, the largest turn of an interval (``inf``: no refinement).
        L: rod length.
        floor: distance to ``centre`` below which a sample is at it.

    Returns:
        ``(owner, t)``, refined.
    """
    kind_a = np.asarray(kind_a)
    rel = points(kind_a[owner], data_a[owner], t, L) - centre[owner]
    r = np.hypot(rel[:, 0], rel[:, 1])
    ang = np.arctan2(rel[:, 1], rel[:, 0])
    k = np.flatnonzero(owner[1:] == owner[:-1])  # intervals to check: (k, k + 1)
    for _ in range(_REFINE):
        turn = np.abs((ang[k + 1] - ang[k] + np.pi) % (2.0 * np.pi) - np.pi)
        split = (turn > sweep[owner[k]]) & (r[k] > floor) & (r[k + 1] > floor)
        split &= t[k + 1] - t[k] > 1e-12 * (np.abs(t[k + 1]) + np.abs(t[k]) + L)
        k = k[split]
        if len(k) == 0:
            break
        tm = 0.5 * (t[k] + t[k + 1])
        rm = points(kind_a[owner[k]], data_a[owner[k]], tm, L) - centre[owner[k]]
        t = np.insert(t, k + 1, tm)
        owner = np.insert(owner, k + 1, owner[k])
        r = np.insert(r, k + 1, np.hypot(rm[:, 0], rm[:, 1]))
        ang = np.insert(ang, k + 1, np.arctan2(rm[:, 1], rm[:, 0]))
        left = k + np.arange(len(k))  # where each split interval's left end is now
        k = np.concatenate([left, left + 1])
        k.sort()
    return owner, t


def sampled_roots(
    kind_a,
    data_a,
    owner,
    t,
    kind_b,
    data_b,
    L: float,
    touch: float,
    rounding: float = 0.0,
    merge: float = np.inf,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zeros of ``g(t) = F_B(P_A(t))`` along sampled curves A (pairs ``owner``).

    Args:
        kind_a, data_a: per pair, the sampled curve A.
        owner: (m,) pair of each sample, sorted, samples increasing within a pair.
        t: (m,) sample parameters on A.
        kind_b, data_b: per pair, the curve B whose implicit function is followed.
        L: rod length.
        touch: extrema of |g| at most this are tangencies (one root at the extremum).
        rounding, merge: |g| at most ``rounding`` is zero to rounding, its sign noise. A
            sign change that rests on such a value at A's end (the end lies on B, and the
            noding records it there), from that end to the next sample or past an
            extremum of g that small, is no second crossing: bisecting the noise put one
            wherever the curves stay within rounding of each other (a type-5 conchoid
            tangent to the type-2 arc of a notch's corner, curvatures equal within 1e-4:
            1.5e-6 to 7.9e-6 from the end, two edges no rotation can order). Such a root
            is dropped unless g half-way between it and that end has, by more than
            ``rounding``, the sign opposite to the bracket's other end (a sign change
            beyond noise: the curve leaves B the other way and crosses back), or it lies
            within ``merge`` of that end (the end's vertex anyway: the same to the bit).

    Returns:
        ``(pair, tA, touching)``: roots on A and whether each is a tangency.
    """
    ka, da = np.asarray(kind_a)[owner], data_a[owner]
    kb, db = np.asarray(kind_b)[owner], data_b[owner]

    def g(sel, tt):
        return implicit(kb[sel], db[sel], points(ka[sel], da[sel], tt, L), L)

    def dg(sel, tt):
        d1, _ = derivatives(ka[sel], da[sel], tt, L)
        grad = gradient(kb[sel], db[sel], points(ka[sel], da[sel], tt, L), L)
        return (d1 * grad).sum(axis=1)

    allidx = np.arange(len(t))
    val = g(allidx, t)
    same = owner[1:] == owner[:-1]
    fin = np.isfinite(val)
    ok = same & fin[1:] & fin[:-1]
    left = np.flatnonzero(ok & (np.sign(val[1:]) * np.sign(val[:-1]) < 0))
    zero = np.flatnonzero(fin & (val == 0.0))
    # brackets [t_k, t_k+1] with a sign change
    lo_i, hi_i = left, left + 1
    # the end a sign change rests on when g there is zero to rounding (nan: none)
    first = np.concatenate([[True], owner[1:] != owner[:-1]])
    last = np.concatenate([owner[1:] != owner[:-1], [True]])
    at_lo = first[lo_i] & (np.abs(val[lo_i]) <= rounding)
    at_hi = last[hi_i] & (np.abs(val[hi_i]) <= rounding)
    rest = np.where(at_lo, t[lo_i], np.where(at_hi, t[hi_i], np.nan))
    beyond = np.sign(np.where(at_lo, val[hi_i], val[lo_i]))  # g's sign at the other sample
    brackets = [(owner[lo_i], t[lo_i], t[hi_i], val[lo_i], rest, beyond)]
    brackets += _end_brackets(owner, t, val, fin, touch, g, dg, rounding)
    # local extrema of |g| between samples of one sign: refine, then split or touch
    mid = (
        np.flatnonzero(
            ok[:-1]
            & ok[1:]
            & (np.sign(val[:-2]) == np.sign(val[1:-1]))
            & (np.sign(val[2:]) == np.sign(val[1:-1]))
            & (np.abs(val[1:-1]) <= np.abs(val[:-2]))
            & (np.abs(val[1:-1]) <= np.abs(val[2:]))
        )
        + 1
    )
    touch_pair = np.zeros(0, dtype=np.intp)
    touch_t = np.zeros(0)
    if len(mid):
        sgn = np.sign(val[mid])
        a, b = t[mid - 1], t[mid + 1]
        # the extremum of sgn * g: the zero of its derivative, bisected to full precision
        slope_a, slope_b = sgn * dg(mid, a), sgn * dg(mid, b)
        ok_b = (slope_a < 0) & (slope_b > 0)
        mid, sgn, a, b = mid[ok_b], sgn[ok_b], a[ok_b], b[ok_b]
        for _ in range(_BISECT):
            m = 0.5 * (a + b)
            up = sgn * dg(mid, m) > 0
            a = np.where(up, a, m)
            b = np.where(up, m, b)
        tm = 0.5 * (a + b)
        fm = sgn * g(mid, tm)
        dips = np.flatnonzero(fm < 0)  # two crossings around the extremum
        if len(dips):
            m = mid[dips]
            none = np.full(len(dips), np.nan)
            brackets.append((owner[m], t[m - 1], tm[dips], val[m - 1], none, none))
            brackets.append((owner[m], tm[dips], t[m + 1], -val[m + 1], none, none))
        near = np.flatnonzero((fm >= 0) & (fm <= touch))
        touch_pair = owner[mid[near]]
        touch_t = tm[near]
    bp = np.concatenate([b[0] for b in brackets])
    ba = np.concatenate([b[1] for b in brackets])
    bb = np.concatenate([b[2] for b in brackets])
    bs = np.sign(np.concatenate([b[3] for b in brackets]))  # sign of g at ba
    rest = np.concatenate([b[4] for b in brackets])
    beyond = np.concatenate([b[5] for b in brackets])
    if len(bp):
        sel = _sample_index(owner, bp)
        for _ in range(_BISECT):
            m = 0.5 * (ba + bb)
            same_sign = np.sign(g(sel, m)) == bs
            ba = np.where(same_sign, m, ba)
            bb = np.where(same_sign, bb, m)
        noisy = np.flatnonzero(np.isfinite(rest))
        if len(noisy):  # a root is certified by g beyond rounding between it and the end
            s = sel[noisy]
            root = 0.5 * (ba + bb)[noisy]
            far = np.hypot(
                *(points(ka[s], da[s], root, L) - points(ka[s], da[s], rest[noisy], L)).T
            )
            half = g(s, 0.5 * (root + rest[noisy]))
            real = (np.abs(half) > rounding) & (np.sign(half) == -beyond[noisy])
            keep = np.ones(len(bp), dtype=bool)
            keep[noisy[(far > merge) & ~real]] = False
            bp, ba, bb = bp[keep], ba[keep], bb[keep]
    pair = np.concatenate([bp, owner[zero], touch_pair])
    tA = np.concatenate([0.5 * (ba + bb), t[zero], touch_t])
    touching = np.concatenate(
        [np.zeros(len(bp) + len(zero), dtype=bool), np.ones(len(touch_pair), dtype=bool)]
    )
    return pair.astype(np.intp), tA, touching


def _end_brackets(owner, t, val, fin, touch, g, dg, rounding=0.0):
    """A curve ending on B may cross B again before its next sample: g is zero at the end
    and has one sign at the next sample, but leaves the end the other way. Bracket that
    second root: between the extremum (a zero of g', bisected) and the next sample. The
    end (its parameter; nan if not) is where the sign change rests when g at the
    extremum is at most ``rounding`` (see :func:`sampled_roots`)."""
    out = []
    n = len(t)
    first = np.flatnonzero(np.concatenate([[True], owner[1:] != owner[:-1]]))
    last = np.concatenate([first[1:] - 1, [n - 1]])
    for end, nb in ((first, first + 1), (last, last - 1)):
        ok = (nb >= 0) & (nb < n)
        end, nb = end[ok], nb[ok]
        ok = (owner[nb] == owner[end]) & fin[end] & fin[nb] & (np.abs(val[end]) <= touch)
        ok &= val[nb] != 0.0
        end, nb = end[ok], nb[ok]
        if len(end) == 0:
            continue
        s_nb = np.sign(val[nb])
        toward = np.where(nb > end, 1.0, -1.0)  # direction from the end to its neighbour
        leaves = np.sign(toward * dg(end, t[end])) == -s_nb  # g first goes the other way
        end, nb, s_nb, toward = end[leaves], nb[leaves], s_nb[leaves], toward[leaves]
        if len(end) == 0:
            continue
        a, b = t[end], t[nb]  # the extremum: where toward * g' turns to sign s_nb
        good = np.sign(toward * dg(end, b)) == s_nb
        end, nb, s_nb, toward, a, b = (x[good] for x in (end, nb, s_nb, toward, a, b))
        for _ in range(_BISECT):
            m = 0.5 * (a + b)
            turned = np.sign(toward * dg(end, m)) == s_nb
            b = np.where(turned, m, b)
            a = np.where(turned, a, m)
        ext = 0.5 * (a + b)
        gext = g(end, ext)
        cross = np.sign(gext) == -s_nb
        lo = np.minimum(ext, t[nb])[cross]
        hi = np.maximum(ext, t[nb])[cross]
        glo = np.where(ext < t[nb], gext, val[nb])[cross]
        rest = np.where(np.abs(gext) <= rounding, t[end], np.nan)[cross]
        out.append((owner[end[cross]], lo, hi, glo, rest, s_nb[cross]))
    return out


def _sample_index(owner: np.ndarray, pair: np.ndarray) -> np.ndarray:
    """Index of a sample of each pair (for the per-sample curve data in ``g``)."""
    first = np.searchsorted(owner, pair)
    return first
