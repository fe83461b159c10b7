// How the volume term of the stable Neo-Hookean energy is integrated (elastic_energy.h,
// nodal_volume_energy.h): a choice the scene and the model files may state.
#pragma once

#include <string>

namespace btr {

/// How the volume term lambda/2 (J - 1)^2 is integrated: per element (the thesis's linear
/// tetrahedra, which lock as nu -> 0.5), or on nodal averages (NodalVolumeEnergy). Auto:
/// nodal from kNodalVolumeFromPoisson up.
enum class VolumeForm { Auto, Element, Nodal };
/// Measured (BENCHMARKS.md): the nodal form is the more accurate in bending at every nu from
/// 0.45 to 0.4999 (a cantilever against beam theory) and on the phantom from nu = 0.499 up, and
/// it makes a registration slower (its Hessian couples each vertex's patch: 2.2 times on SfePy's
/// fat-1000 body with E estimated since 2026-12-05, 3.5 to 5 times before). The threshold keeps
/// the thesis's nu = 0.49 on the element form: with the nodal form as the default (tried,
/// BENCHMARKS.md, "The nodal volume term as the default") the suite folded coarse soft meshes on
/// three bodies (9 to 24 of 28 runs not converged at fat 300 to 500 Pa, 0 to 4 with the element
/// form), although from 1000 Pa up and with the full method it is the nearer model on both
/// independent bodies. `material.volume_form: nodal` chooses it at any nu (BENCHMARKS.md, "The
/// nodal volume term's cost"); `material.nodal_element_share` converges some of those folding
/// runs at a cost in accuracy (BENCHMARKS.md, "The nodal form with an element share"). Since
/// 2026-12-06 a preset may take the nodal form where a scene leaves it to auto and unloads
/// (RegistrationOptions::volume_form; the balanced preset does, at 9 mm: BENCHMARKS.md, "The
/// presets' front with the volume form"; the accurate preset at 5 mm: "The balanced preset's
/// fallback, and one mesh is one draw").
constexpr double kNodalVolumeFromPoisson = 0.495;
VolumeForm resolve_volume_form(VolumeForm form, double poisson_ratio);
/// Parses "auto", "element" or "nodal"; InputError otherwise.
VolumeForm parse_volume_form(const std::string& s);
const char* to_string(VolumeForm form);

}  // namespace btr
