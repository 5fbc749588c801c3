#pragma once
/// @file error.hpp
/// The one error type interpatch throws for bad input, and the codes it carries.

#include <stdexcept>
#include <string>
#include <string_view>

namespace interpatch {

/// What is wrong. Every public function documents the codes it can raise.
enum class errc {
  // --- invalid input (spec or data); the command line exits with 3 ---
  invalid_json,            ///< the spec is not valid JSON
  missing_field,           ///< a required field is absent
  wrong_type,              ///< a field has the wrong JSON type or an unknown value
  unknown_type,            ///< the spec's "type" names no construction
  not_finite,              ///< NaN or Inf in a coordinate, parameter, knot or weight
  ragged_grid,             ///< rows of a grid differ in length, or a point is not 3 numbers
  too_few_points,          ///< fewer points than the degree needs
  invalid_degree,          ///< degree < 1, or too high for the data
  zero_chord,              ///< coincident consecutive points where parameters must increase
  non_increasing,          ///< parameters or knots that must increase do not
  invalid_knots,           ///< knot vector not clamped, multiplicity too high, wrong count
  invalid_weight,          ///< a rational weight <= 0
  size_mismatch,           ///< arrays that must agree in size do not
  out_of_domain,           ///< a parameter outside the domain
  singular,                ///< the linear system has no unique solution
  corner_gap,              ///< boundary curves do not meet at a corner
  network_gap,             ///< curves of a network miss each other
  network_order,           ///< curves of a network cross in orders no sorting makes agree, or meet within a family
  incompatible_twist,      ///< given twists disagree with the cross-derivative curves
  tangent_mismatch,        ///< cross-derivative curves disagree with the boundary tangents at a corner
  invalid_blend,           ///< a blending function that is not 0 at 0, 1 at 1 and monotone
  no_exact_form,           ///< the construction has no exact B-spline form (e.g. Gregory's rational twists)
  malformed_file,          ///< a data file is readable but not well formed (NPY header, CSV field)
  closing_gap,             ///< a closed shape's last point nearly, but not quite, repeats the first
  tolerance_not_met,       ///< an approximation cannot bring every data point within the tolerance asked for; a network cannot re-express its curves within theirs
  ill_conditioned,         ///< a fit's control points swing far outside its data (a near-singular system)
  invalid_grading,         ///< a mesh grading that cannot be: a non-positive length or ratio, an end longer than its direction
  block_mismatch,          ///< blocks whose faces nearly meet, or meet with different node counts or apart along the face
  // --- files; the command line exits with 4 ---
  file_unreadable,         ///< a file cannot be opened or read
  file_unwritable,         ///< an output file cannot be written
  // --- resources; the command line exits with 5 ---
  too_large,               ///< the work needs more memory than this machine has
  // --- anything else; the command line exits with 1 ---
  internal,
};

/// The name of a code, e.g. "zero_chord".
std::string_view to_string(errc code) noexcept;

/// Bad input at the API. The message names the place (a JSON Pointer, a file
/// with row and column, a curve, a corner, an index) and the size of the problem.
class error : public std::runtime_error {
 public:
  error(errc code, const std::string& message) : std::runtime_error(message), code_(code) {}
  [[nodiscard]] errc code() const noexcept { return code_; }

 private:
  errc code_;
};

}  // namespace interpatch
