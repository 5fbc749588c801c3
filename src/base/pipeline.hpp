#pragma once
// An output made a block at a time by every thread while the block before it is
// written: the writing (the kernel copying the bytes into the page cache, about
// as long as the evaluation of a surface's points) no longer leaves the other
// core idle.

#include <cstddef>
#include <exception>
#include <limits>

#include "base/parallel.hpp"

namespace interpatch::detail {

/// Makes blocks 0 .. blocks − 1 and hands each to `write`, in order. Block b is made
/// in pieces(b) pieces, make(b, p), shared by every thread as each comes free,
/// while one thread calls write(b − 1) and then joins them; so two blocks are alive
/// at once, and a block's memory can be reused two blocks later (buffer b % 2).
/// pieces(b) is called by every thread outside the catching below and must not
/// throw. make must give the same bits on whichever thread makes a piece; nested parallel
/// regions inside it run on the calling thread (OpenMP's default). With `parallel`
/// false, or one thread, the same calls run one after another.
///
/// The first failure in block order (and piece order inside a block) stops the work:
/// no block after it is made or written, and its exception is rethrown here,
/// whichever thread met it: the failure a run on one thread meets.
template <class Pieces, class Make, class Write>
void pipeline(std::size_t blocks, bool parallel, Pieces&& pieces, Make&& make, Write&& write) {
  std::exception_ptr error;
  // (block, piece) of the failure kept; write(b − 1) counts as piece 0 of block b,
  // ahead of block b's own pieces (it runs beside them, but comes first in order).
  // Pieces of the failing block still run, so that the first of its failures is the
  // one reported; nothing of a later block is made or written.
  std::size_t error_block = std::numeric_limits<std::size_t>::max(), error_piece = 0;
  const auto attempt = [&](std::size_t b, std::size_t p, auto&& f) {
    std::size_t failed_block = 0;
#pragma omp atomic read
    failed_block = error_block;
    if (b > failed_block) return;
    try {
      f();
    } catch (...) {
#pragma omp critical(interpatch_pipeline_error)
      if (b < error_block || (b == error_block && p < error_piece)) {
        error = std::current_exception();
        error_piece = p;
#pragma omp atomic write
        error_block = b;
      }
    }
  };
  constexpr std::size_t write_piece = 0;  // write(b − 1) before block b's pieces
#pragma omp parallel if (parallel)
  for (std::size_t b = 0; b <= blocks; ++b) {
    if (b > 0) {
#pragma omp single nowait
      attempt(b, write_piece, [&] { write(b - 1); });
    }
    if (b < blocks) {
      const std::size_t n = pieces(b);
#pragma omp for schedule(dynamic, 1)
      for (std::size_t p = 0; p < n; ++p) attempt(b, p + 1, [&] { make(b, p); });
    } else {
#pragma omp barrier
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace interpatch::detail
