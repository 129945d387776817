"""Removing one object's lighting effects from the panorama (thesis chapters 3-4).

Three scales work together:
  * coarse patches over the whole room (`room`): radiosity from the panorama, reflectance,
    estimates for what the probe cannot see, and the propagation of the change for several
    bounces (`propagation`); the few patches whose light varies within them (under the
    object's contact, at its shadow's edge) send through sub-triangles (`first_order`);
  * a fine lattice near the object (`irradiance`): the light of the many unimportant senders
    and of the object itself, interpolated to pixels (the thesis's coarse grid of corners);
  * each affected pixel's own 3D point and normal (`local`): the important senders (lamps)
    that the object shadows, with exact form factors and sampled visibility.
The new radiance is the ratio form L' = L (E + dE) / E (differential rendering, `compose`), so
errors in E cancel and texture is kept; where the object was, reflectance is synthesised and
lit anew (`fill`). Only a difference image is returned. `sequence` runs the stages in order;
each returns a frozen result that the next takes. See docs/design.md for the method.

Glossary:
  B     radiosity (W/m^2, per colour channel); B = pi L on a diffuse surface
  L     radiance, the panorama's pixel values
  E     irradiance; E' after the removal; dE = E' - E, the change of irradiance
  db    the change of the patches' radiosity, every bounce
  rho   reflectance (albedo), rho = B / E, kept below RHO_MAX
  T, T' transport (form factor times visibility) with the object and without it
  _h    suffix of an array with one row per hit pixel (`Traced.hp`: pixels whose ray meets
        the proxy), e.g. `e_h`, `tri_h`
  patch a piece of a proxy triangle on the coarse lattice (or a cluster of a detailed
        object's triangles); sender: a patch as a source of light for the others
"""
from .sequence import RemovalResult, finish, finish_full_size, remove, solve, solve_lighting, traced_scene
from .solution import Solution

__all__ = ["RemovalResult", "Solution", "finish", "finish_full_size", "remove", "solve", "solve_lighting",
           "traced_scene"]
