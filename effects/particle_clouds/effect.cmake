# Particle clouds (issue 22; physics.md): cumulus built from spherical
# particles, each lit from a precomputed table of the light scattered inside
# a reference particle (18 orders, iterated from single scattering). The
# particles are modelled per frame on the CPU (rings of cells around the
# viewer, extruded into voxels), shadowed through a coarse lattice, sorted and
# binned into screen tiles; the shading pass composites each pixel's
# particles through its view_transfer hook. After the noise clouds, whose
# media_segment_transfer it uses; a scene has one of the two.
set(EFFECT_SOURCES sphere_scattering.cpp particle_table.cpp particle_field.cpp particle_keys.cpp
    particle_frame.cpp)
set(EFFECT_SCENE_KEYS particle_clouds)
set(EFFECT_GLSL_MATH particle_table_math.glsl)  # the table's node coordinates, shared with the CPU
set(EFFECT_GLSL_PIXEL particle_clouds.glsl)
set(EFFECT_GLSL_TERMS particle_terms.glsl)
set(EFFECT_HOOKS
    view_transfer=particle_clouds_view_transfer)
set(EFFECT_FEATURES
    particle_clouds=HAS_PARTICLE_CLOUDS)  # particle clouds with some coverage and extinction
set(EFFECT_TABLES
    particle_light  # the lighting table (physics.md section 3): RGBA, (azimuth + A zenith, entry + E tau slice)
    particles       # the frame's particles, two RGBA texels each (centre, radius; tau, sun and sky transmittance)
    particle_tiles  # the screen tiles' offsets, then their lists of particle indices
    particle_shadow) # the sun's transmittance through the particles from the plane below them
set(EFFECT_FRAME 1)
set(EFFECT_GLSL_LAYOUT particle_layout.glsl)
set(EFFECT_UNIFORMS "ParticleCloudsGpu particle_clouds")
set(EFFECT_SCENE_HEADER particle_clouds_scene.hpp)
set(EFFECT_SCENE_MEMBERS "ParticleClouds particle_clouds")
set(EFFECT_QUALITY ParticleCloudsQuality)
set(EFFECT_QUALITY_KEYS particle_table particle_compositing)
set(EFFECT_LAYERS
    "particle_clouds=the sun's and the sky's light scattered toward the camera by the particle clouds")
