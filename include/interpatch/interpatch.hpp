#pragma once
/// @file interpatch.hpp
/// Everything of interpatch in one include: the core (core.hpp) and the readers and
/// writers of io/ (library interpatch::interpatch, which links both).

#include "interpatch/core.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/io/csv.hpp"
#include "interpatch/io/iges.hpp"
#include "interpatch/io/input.hpp"
#include "interpatch/io/json_out.hpp"
#include "interpatch/io/mesh.hpp"
#include "interpatch/io/npy.hpp"
#include "interpatch/io/npz.hpp"
#include "interpatch/io/outputs.hpp"
#include "interpatch/io/project.hpp"
#include "interpatch/io/spec.hpp"
#include "interpatch/io/step.hpp"
#include "interpatch/io/view.hpp"
