# Particle clouds (issue 22; physics.md): cumulus built from spherical
# particles, each lit from a precomputed table of the light scattered inside
# a reference particle (18 orders, iterated from single scattering).
set(EFFECT_SOURCES sphere_scattering.cpp particle_table.cpp)
