"""Shaking force and rocking moment of an inline engine (course sections 1, 7.3, figure 1).

Each cylinder is the compressor's slider-crank (course section 4): crank radius R, rod
length L, ratio ``λ = R / L`` (here λ is the crank ratio, not the compressor's piston
abscissa OB). Its rod is reduced to two point masses as usual: the **reciprocating mass**
``m`` (piston and the small end of the rod) slides along the cylinder's axis y0, and the
**rotating mass** ``m_rot`` (crank pin and big end) turns at radius R.

Frame of the block (the compressor's B0): y0 along the cylinders towards their heads,
x0 across them, z0 along the crankshaft; the block's centre C is on the crankshaft midway
between the end cylinders, cylinder i sits at ``z_i = (i − (n − 1)/2) a``. θ is the crank
angle of cylinder 1 from its top dead centre (the compressor's angle is θ + 90°) and
cylinder i is at ``ψ_i = θ − φ_i`` from its own, with the throws φ = 0 (one cylinder),
0-180° (twin) and 0-180-180-0° (flat-crank four). Constant speed ω, weight neglected.

Force the moving parts transmit to the block, ``−Σ m Γ`` (the pilon along y0, the tamis
along x0), for one cylinder:

- reciprocating, exact: ``m ω² (R cos ψ + R² cos 2ψ / q + R⁴ sin² ψ cos² ψ / q³)``,
  ``q = √(L² − R² sin² ψ)``; its first two orders ``m R ω² (cos ψ + λ cos 2ψ)``;
- rotating: ``u R ω² (−sin ψ, cos ψ)`` with the net rotating mass
  ``u = (1 − k_rot) m_rot − k_rec m`` left by a counterweight of ``k_rot m_rot + k_rec m``
  at radius R opposite each throw (the course's "balourd" on the shaft, section 1: it
  trades the fraction k_rec of the first-order pilon for as much tamis).

A Lanchester pair (two shafts at 2ω turning opposite ways, at C) adds ``−β`` times the
engine's two-term second-order pilon; their tamis cancel and they add no moment.
Rocking moment about C: ``M_C = Σ z_i z0 ∧ F_i = Σ z_i (−F_y,i, F_x,i)``.

Order k of the pilon sums ``e^{−ikφ_i}``: the flat four gives 0 at order 1 and 4 at
order 2 (its second order is four times one cylinder's), the twin 0 and 2. The moment
sums ``z_i e^{−ikφ_i}``: 0 for the four at both orders, ``−a`` for the twin at order 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

RPM = 2 * math.pi / 60
"""rad/s per tr/min."""

THROWS_DEG: dict[int, tuple[float, ...]] = {1: (0.0,), 2: (0.0, 180.0), 4: (0.0, 180.0, 180.0, 0.0)}
"""Crank throws φ_i [°] of the inline engines (flat crank for the four)."""


@dataclass(frozen=True)
class Engine:
    """An inline engine at constant speed.

    Attributes:
        cylinders: 1, 2 or 4.
        R: Crank radius [m].
        L: Rod length [m], > R.
        m: Reciprocating mass per cylinder [kg].
        omega: Crank speed ω [rad/s].
        spacing: Distance a between neighbouring cylinders [m].
        m_rot: Rotating mass per throw at radius R [kg].
        k_rot: Counterweight, fraction of ``m_rot`` (0..1).
        k_rec: Counterweight, fraction of ``m`` (0..1).
        balance_shaft: Lanchester pair, fraction β of the second-order pilon cancelled (0..1).

    Raises:
        ValueError: naming the parameter out of its range.
    """

    cylinders: int
    R: float
    L: float
    m: float
    omega: float
    spacing: float = 0.1
    m_rot: float = 0.0
    k_rot: float = 0.0
    k_rec: float = 0.0
    balance_shaft: float = 0.0

    def __post_init__(self) -> None:
        if self.cylinders not in THROWS_DEG:
            raise ValueError(f"cylinders must be 1, 2 or 4, got {self.cylinders!r}")
        if not self.R > 0:
            raise ValueError(f"R must be > 0 m, got {self.R!r}")
        if not self.L > self.R:
            raise ValueError(f"L must exceed R = {self.R!r} m, got {self.L!r}")
        for name in ("m", "m_rot", "omega"):
            if not getattr(self, name) >= 0:
                raise ValueError(f"{name} must be >= 0, got {getattr(self, name)!r}")
        if not self.spacing > 0:
            raise ValueError(f"spacing must be > 0 m, got {self.spacing!r}")
        for name in ("k_rot", "k_rec", "balance_shaft"):
            if not 0 <= getattr(self, name) <= 1:
                raise ValueError(f"{name} must be in [0, 1], got {getattr(self, name)!r}")

    @property
    def lam(self) -> float:
        """Crank ratio λ = R / L."""
        return self.R / self.L

    @property
    def throws(self) -> np.ndarray:
        """φ_i [rad], shape (n,)."""
        return np.radians(THROWS_DEG[self.cylinders])

    @property
    def positions(self) -> np.ndarray:
        """z_i [m] of the cylinders from the block's centre C, shape (n,)."""
        n = self.cylinders
        return (np.arange(n) - (n - 1) / 2) * self.spacing

    @property
    def net_rotating(self) -> float:
        """u = (1 − k_rot) m_rot − k_rec m [kg]: rotating mass left at R on each throw."""
        return (1 - self.k_rot) * self.m_rot - self.k_rec * self.m


def piston_acceleration(psi: np.ndarray | float, R: float, L: float, omega: float) -> np.ndarray:
    """Exact acceleration [m/s²] along y0 of a piston at ψ from top dead centre.

    y = R cos ψ + q, q = √(L² − R² sin² ψ), so at constant ω
    y'' = −ω² (R cos ψ + R² cos 2ψ / q + R⁴ sin² ψ cos² ψ / q³).
    """
    p = np.asarray(psi, dtype=float)
    s, c = np.sin(p), np.cos(p)
    q = np.sqrt(L * L - (R * s) ** 2)
    return -(omega**2) * (R * c + R * R * np.cos(2 * p) / q + R**4 * (s * c) ** 2 / q**3)


def _cylinder_forces(e: Engine, theta: np.ndarray, exact: bool) -> np.ndarray:
    """(x0, y0) force of each cylinder on the block, shape theta.shape + (n, 2)."""
    psi = theta[..., None] - e.throws
    w2 = e.omega**2
    if exact:
        axial = -e.m * piston_acceleration(psi, e.R, e.L, e.omega)
    else:
        axial = e.m * e.R * w2 * (np.cos(psi) + e.lam * np.cos(2 * psi))
    u = e.net_rotating * e.R * w2
    return np.stack([-u * np.sin(psi), axial + u * np.cos(psi)], axis=-1)


def cylinder_forces(e: Engine, theta: np.ndarray | float, *, exact: bool = True) -> np.ndarray:
    """Force [N] each cylinder (piston, rod, throw and its counterweight) transmits to the
    block, components (x0, y0), shape ``theta.shape + (n, 2)`` (the Lanchester pair apart).
    """
    return _cylinder_forces(e, np.asarray(theta, dtype=float), exact)


def _shaft_force(e: Engine, theta: np.ndarray) -> np.ndarray:
    """(x0, y0) force of the Lanchester pair: −β Σ m R ω² λ cos 2ψ_i along y0."""
    second = np.cos(2 * (theta[..., None] - e.throws)).sum(axis=-1)
    axial = -e.balance_shaft * e.m * e.R * e.omega**2 * e.lam * second
    return np.stack([np.zeros_like(axial), axial], axis=-1)


def shaking_force(e: Engine, theta: np.ndarray | float, *, exact: bool = True) -> np.ndarray:
    """Force the moving parts transmit to the block [N], components (x0, y0).

    Args:
        e: The engine.
        theta: Crank angle of cylinder 1 from its top dead centre [rad], any shape.
        exact: True: the exact slider-crank; False: the first two orders only.

    Returns:
        Shape ``theta.shape + (2,)``: the tamis (x0) and the pilon (y0).
    """
    t = np.asarray(theta, dtype=float)
    return _cylinder_forces(e, t, exact).sum(axis=-2) + _shaft_force(e, t)


def shaking_moment(e: Engine, theta: np.ndarray | float, *, exact: bool = True) -> np.ndarray:
    """Rocking moment at the block's centre C [N·m], components (x0, y0).

    M_C = Σ z_i (−F_y,i, F_x,i): the pilons pitch the block about x0, the tamis yaw it
    about y0. The balance shafts sit at C and add nothing. Shape ``theta.shape + (2,)``.
    """
    f = _cylinder_forces(e, np.asarray(theta, dtype=float), exact)
    z = e.positions
    return np.stack([-(z * f[..., 1]).sum(axis=-1), (z * f[..., 0]).sum(axis=-1)], axis=-1)


def _order_sum(e: Engine, k: int, weights: np.ndarray | None = None) -> float:
    """|Σ w_i e^{−ikφ_i}| (w_i = 1 for forces, z_i for moments)."""
    w = np.ones(e.cylinders) if weights is None else weights
    return float(abs(np.sum(w * np.exp(-1j * k * e.throws))))


def shaking_force_h1(e: Engine) -> float:
    """Amplitude of the first-order pilon [N]: (m + u) R ω² |Σ e^{−iφ_i}|.

    Exact, not only the two-term formula: the rest of the exact pilon holds even orders only.
    """
    return abs(e.m + e.net_rotating) * e.R * e.omega**2 * _order_sum(e, 1)


def transverse_force_h1(e: Engine) -> float:
    """Amplitude of the first-order tamis [N]: |u| R ω² |Σ e^{−iφ_i}|."""
    return abs(e.net_rotating) * e.R * e.omega**2 * _order_sum(e, 1)


def shaking_force_h2(e: Engine) -> float:
    """Amplitude of the two-term second-order pilon [N]: (1 − β) m R ω² λ |Σ e^{−2iφ_i}|.

    The exact second order is larger by λ³/4 + 15 λ⁵/128 + ... relative to λ (see
    :func:`pilon_orders`).
    """
    return (1 - e.balance_shaft) * e.m * e.R * e.omega**2 * e.lam * _order_sum(e, 2)


def shaking_moment_h1(e: Engine) -> float:
    """Largest first-order rocking moment over a turn [N·m].

    Pitch amplitude |m + u| R ω² |Σ z_i e^{−iφ_i}| and yaw amplitude |u| R ω² |Σ z_i e^{−iφ_i}|
    are in quadrature, so the moment's largest norm is the larger of the two.
    """
    s = e.R * e.omega**2 * _order_sum(e, 1, e.positions)
    return max(abs(e.m + e.net_rotating), abs(e.net_rotating)) * s


def shaking_moment_h2(e: Engine) -> float:
    """Amplitude of the two-term second-order pitch moment [N·m]: m R ω² λ |Σ z_i e^{−2iφ_i}|."""
    return e.m * e.R * e.omega**2 * e.lam * _order_sum(e, 2, e.positions)


def shaking_moment_amplitude(e: Engine, *, exact: bool = True, samples: int = 720) -> float:
    """Largest norm of the rocking moment over one turn [N·m], sampled at ``samples`` angles."""
    theta = np.linspace(0, 2 * math.pi, samples, endpoint=False)
    return float(np.linalg.norm(shaking_moment(e, theta, exact=exact), axis=-1).max())


def pilon_orders(e: Engine, orders: int = 6, samples: int = 256) -> np.ndarray:
    """Amplitudes [N] of orders 0..``orders`` of the exact pilon (y0), by FFT over one turn.

    For one cylinder without rotating mass, order 1 is m R ω² and order 2 is
    m R ω² (λ + λ³/4 + 15 λ⁵/128 + ...).
    """
    if samples <= 2 * orders:
        raise ValueError(f"samples must exceed 2 × orders = {2 * orders}, got {samples!r}")
    theta = np.linspace(0, 2 * math.pi, samples, endpoint=False)
    coef = np.fft.rfft(shaking_force(e, theta)[:, 1]) / samples
    amp = 2 * np.abs(coef[: orders + 1])
    amp[0] /= 2
    return amp


def lanchester_unbalance(e: Engine) -> float:
    """m·e [kg·m] of each of the two shafts at 2ω that cancels the two-term second order.

    Each shaft pulls with 4 ω² m·e; the pair's pilons add up to 8 ω² m·e against
    m R ω² λ |Σ e^{−2iφ_i}|, so m·e = m R λ |Σ e^{−2iφ_i}| / 8 (m R λ / 2 for the four).
    """
    return e.m * e.R * e.lam * _order_sum(e, 2) / 8


def strokes_per_second(speed_rpm: float) -> float:
    """Round trips of a piston per second [1/s] at ``speed_rpm`` [tr/min] (one per turn)."""
    if not speed_rpm >= 0:
        raise ValueError(f"speed_rpm must be >= 0, got {speed_rpm!r}")
    return speed_rpm / 60
