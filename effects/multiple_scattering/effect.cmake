# Multiple scattering: the plane-parallel radiative transfer solver of the
# daytime atmosphere (physics.md; effects/multiple_scattering/docs/solver.md).
# A standalone unit for now: no shader features or tables yet.
set(EFFECT_SOURCES plane_parallel.cpp)
