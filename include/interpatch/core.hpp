#pragma once
/// @file core.hpp
/// The core of interpatch in one include: curves, surfaces, volumes, the
/// constructions and their evaluation (library interpatch::core; no JSON, no files).

#include "interpatch/allocator.hpp"
#include "interpatch/blend.hpp"
#include "interpatch/blended_surface.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/coons.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/hermite.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/memory.hpp"
#include "interpatch/network.hpp"
#include "interpatch/patches.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/surface.hpp"
#include "interpatch/threads.hpp"
#include "interpatch/vec3.hpp"
#include "interpatch/volume.hpp"
#include "interpatch/volume_patches.hpp"
