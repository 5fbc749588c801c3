#pragma once
/// @file interpatch.hpp
/// Everything of interpatch in one include.

#include "interpatch/allocator.hpp"
#include "interpatch/blended_volume.hpp"
#include "interpatch/bspline_curve.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/bspline_volume.hpp"
#include "interpatch/coons_volume.hpp"
#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/grid.hpp"
#include "interpatch/hermite.hpp"
#include "interpatch/interpolate.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/memory.hpp"
#include "interpatch/progress.hpp"
#include "interpatch/threads.hpp"
#include "interpatch/vec3.hpp"
#include "interpatch/volume.hpp"
#include "interpatch/volume_patches.hpp"
