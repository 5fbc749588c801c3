#include "interpatch/error.hpp"

namespace interpatch {

std::string_view to_string(errc code) noexcept {
  switch (code) {
    case errc::invalid_json: return "invalid_json";
    case errc::missing_field: return "missing_field";
    case errc::wrong_type: return "wrong_type";
    case errc::unknown_type: return "unknown_type";
    case errc::not_finite: return "not_finite";
    case errc::ragged_grid: return "ragged_grid";
    case errc::too_few_points: return "too_few_points";
    case errc::invalid_degree: return "invalid_degree";
    case errc::zero_chord: return "zero_chord";
    case errc::non_increasing: return "non_increasing";
    case errc::invalid_knots: return "invalid_knots";
    case errc::invalid_weight: return "invalid_weight";
    case errc::size_mismatch: return "size_mismatch";
    case errc::out_of_domain: return "out_of_domain";
    case errc::singular: return "singular";
    case errc::corner_gap: return "corner_gap";
    case errc::network_gap: return "network_gap";
    case errc::network_order: return "network_order";
    case errc::incompatible_twist: return "incompatible_twist";
    case errc::tangent_mismatch: return "tangent_mismatch";
    case errc::invalid_blend: return "invalid_blend";
    case errc::no_exact_form: return "no_exact_form";
    case errc::malformed_file: return "malformed_file";
    case errc::closing_gap: return "closing_gap";
    case errc::tolerance_not_met: return "tolerance_not_met";
    case errc::ill_conditioned: return "ill_conditioned";
    case errc::invalid_grading: return "invalid_grading";
    case errc::block_mismatch: return "block_mismatch";
    case errc::file_unreadable: return "file_unreadable";
    case errc::file_unwritable: return "file_unwritable";
    case errc::too_large: return "too_large";
    case errc::internal: return "internal";
  }
  return "internal";
}

}  // namespace interpatch
