// Which sigma points a rank runs: S split into R contiguous shares as even as can be, the
// first S mod R ranks one more (S = 17 on 3 ranks: 6, 6, 5). Rank 0 gathers the shares in
// rank order, so sigma point s is always column s, whatever R.
#pragma once

namespace sigmafem {

struct SigmaShare {
  int first = 0;   // the rank's first sigma point
  int count = 0;   // and how many
};

inline SigmaShare sigma_share(int sigma_count, int ranks, int rank) {
  const int base = sigma_count / ranks, extra = sigma_count % ranks;
  return {rank * base + (rank < extra ? rank : extra), base + (rank < extra ? 1 : 0)};
}

}  // namespace sigmafem
