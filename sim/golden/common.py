"""The one signature every float64 golden model shares.

Inputs are per-pixel arrays of polar angles in radians (docs/algorithms.md): theta from +z in
[0, pi], phi the azimuth in [0, 2*pi]. N, L and H are in world angles; the bump normal
N' (``b_phi``, ``b_theta``) is in tangent space. The tangent frame is the one the Lee
paper's two rotations define (Sec. 3.1.1, Figs 1-2): rotate by -phi_N about z, then by
-theta_N about y, so that N becomes +z.
"""

from dataclasses import dataclass, fields

import numpy as np

from bumprtl.rtl.config import BumpError, Config

__all__ = ["PixelInputs", "Result", "polar_to_cartesian", "cartesian_to_polar",
           "tangent_rotation", "world_bump_normal", "shade", "to_8bit"]

TWO_PI = 2 * np.pi


@dataclass(frozen=True)
class PixelInputs:
    """Per-pixel angles (radians), all arrays of one shape, float64."""
    n_phi: np.ndarray
    n_theta: np.ndarray
    l_phi: np.ndarray
    l_theta: np.ndarray
    h_phi: np.ndarray
    h_theta: np.ndarray
    b_phi: np.ndarray
    b_theta: np.ndarray

    def __post_init__(self):
        shape = None
        for f in fields(self):
            raw = getattr(self, f.name)
            arr = np.asarray(raw)
            if arr.dtype.kind not in "fiu":
                raise BumpError(f"{f.name} must be a real-valued array, got dtype {arr.dtype}")
            arr = arr.astype(np.float64)
            if shape is None:
                shape = arr.shape
            elif arr.shape != shape:
                raise BumpError(f"{f.name} has shape {arr.shape}, expected {shape} like n_phi")
            if not np.all(np.isfinite(arr)):
                raise BumpError(f"{f.name} contains NaN or infinity")
            hi = np.pi if f.name.endswith("theta") else TWO_PI
            if arr.size and (arr.min() < 0 or arr.max() > hi):
                bad = arr.min() if arr.min() < 0 else arr.max()
                raise BumpError(f"{f.name} = {bad:.6g} rad is out of range: allowed [0, "
                                f"{'pi' if hi == np.pi else '2*pi'}]")
            object.__setattr__(self, f.name, arr)

    @property
    def shape(self):
        return self.n_phi.shape

    def __len__(self):
        return self.n_phi.size

    def subset(self, index):
        return PixelInputs(**{f.name: getattr(self, f.name)[index] for f in fields(self)})

    @classmethod
    def concat(cls, sets):
        """One PixelInputs of the pixels of ``sets``, in order."""
        return cls(**{f.name: np.concatenate([getattr(p, f.name) for p in sets])
                      for f in fields(cls)})

    @classmethod
    def random(cls, n, rng, valid=True):
        """``n`` random pixels. ``valid``: N' in the upper tangent hemisphere and L, H above
        the surface (N.L > 0, N.H > 0), the inputs a renderer actually produces."""
        def uniform_dirs(count, upper):
            z = rng.uniform(0.0 if upper else -1.0, 1.0, count)
            return rng.uniform(0, TWO_PI, count), np.arccos(np.clip(z, -1, 1))
        out = {}
        out["n_phi"], out["n_theta"] = uniform_dirs(n, False)
        out["b_phi"], out["b_theta"] = uniform_dirs(n, valid)
        for v in ("l", "h"):
            phi, theta = uniform_dirs(n, False)
            if valid:   # redraw until above the surface of N
                nvec = polar_to_cartesian(out["n_phi"], out["n_theta"])
                bad = np.arange(n)          # the pixels to check: a redrawn one only
                for _ in range(64):
                    below = np.einsum("...i,...i", polar_to_cartesian(phi[bad], theta[bad]),
                                      nvec[bad]) <= 0.02
                    bad = bad[below]
                    if not bad.size:
                        break
                    phi[bad], theta[bad] = uniform_dirs(bad.size, False)
            out[f"{v}_phi"], out[f"{v}_theta"] = phi, theta
        return cls(**out)


@dataclass(frozen=True)
class Result:
    """What every golden model returns (float64 arrays of the input shape).

    ``ndotl``/``ndoth`` are the raw dot products N'.L' and N'.H' (signed); ``diffuse`` is
    max(0, N'.L'), ``specular`` max(0, N'.H')**n and ``color`` the Phong sum of eq. (2),
    clamped to [0, 1]. ``l_prime`` is (phi, theta) of L in tangent space for the methods that
    compute it (None otherwise).
    """
    ndotl: np.ndarray
    ndoth: np.ndarray
    diffuse: np.ndarray
    specular: np.ndarray
    color: np.ndarray
    l_prime: tuple | None = None


def polar_to_cartesian(phi, theta):
    """Unit vectors (..., 3) from polar angles: (sin th cos ph, sin th sin ph, cos th)."""
    st = np.sin(theta)
    return np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)], axis=-1)


def cartesian_to_polar(v):
    """(phi in [0, 2pi), theta in [0, pi]) of vectors (..., 3); need not be unit length."""
    v = np.asarray(v, dtype=np.float64)
    r = np.linalg.norm(v, axis=-1)
    theta = np.arccos(np.clip(v[..., 2] / np.where(r == 0, 1, r), -1, 1))
    phi = np.mod(np.arctan2(v[..., 1], v[..., 0]), TWO_PI)
    return phi, theta


def tangent_rotation(n_phi, n_theta):
    """Per-pixel 3x3 matrices M = R_y(-theta_N) R_z(-phi_N) (Lee Sec. 3.1.1): M N = +z."""
    cp, sp = np.cos(n_phi), np.sin(n_phi)
    ct, st = np.cos(n_theta), np.sin(n_theta)
    zero, one = np.zeros_like(cp), np.ones_like(cp)
    rz = np.stack([np.stack([cp, sp, zero], -1), np.stack([-sp, cp, zero], -1),
                   np.stack([zero, zero, one], -1)], -2)          # rotation by -phi about z
    ry = np.stack([np.stack([ct, zero, -st], -1), np.stack([zero, one, zero], -1),
                   np.stack([st, zero, ct], -1)], -2)             # rotation by -theta about y
    return ry @ rz


def world_bump_normal(n_phi, n_theta, b_phi, b_theta):
    """The bumped normal N' in world coordinates (..., 3): M^T b with M the tangent rotation
    of the world normal (radians; :func:`tangent_rotation`, Lee Sec. 3.1.1)."""
    m = tangent_rotation(n_phi, n_theta)
    return np.einsum("...ji,...j->...i", m, polar_to_cartesian(b_phi, b_theta))


def shade(ndotl, ndoth, cfg: Config, l_prime=None):
    """Phong, eq. (2) with I_a = I_i = 1: the common back end of every model."""
    diffuse = np.clip(ndotl, 0.0, 1.0)
    specular = np.clip(ndoth, 0.0, 1.0) ** cfg.spec_exponent if cfg.specular else np.zeros_like(ndoth)
    color = np.clip(cfg.ka + cfg.kd * diffuse + cfg.ks * specular, 0.0, 1.0)
    return Result(ndotl, ndoth, diffuse, specular, color, l_prime)


def to_8bit(x):
    """[0, 1] -> 0..255, rounded to nearest (outputs are 8-bit: docs/architecture.md, Number formats). NaN (where the
    printed Lee equations have no value) becomes 0, i.e. black."""
    x = np.nan_to_num(np.asarray(x, dtype=np.float64), nan=0.0)
    return np.clip(np.rint(x * 255.0), 0, 255).astype(np.uint8)
