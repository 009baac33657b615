#pragma once
// Chart tiers: per boat and time bucket of each of kTierWidths_s seconds, the number of samples
// and the four samples a thinned chart keeps (lowest and highest heel, lowest and highest pitch:
// time, heel, pitch and heading of each). A chart of a 4-hour session reads a few thousand tier
// rows instead of 360 000 samples (Store::attitude_tier, GET /boats/{id}/attitude).
//
// Every path that inserts samples (the live writer, backfill, imports) folds the rows it actually
// inserted into a TierFold and writes it in the same transaction, so the tiers are exactly as
// durable as the samples. rebuild_tiers() recomputes a span from the samples themselves, after
// retention deleted some or for a database written before the tiers existed.

#include <sqlite3.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <tuple>

namespace telltale::shore {

/// Creates the tier table if it is missing.
void create_tier_table(sqlite3* db);

/// Rebuilds the tiers of `boat_id` over [from_ns, to_ns] (widened to whole buckets of every width)
/// from the samples there; boat_id empty: every boat, the whole time.
void rebuild_tiers(sqlite3* db, const std::string& boat_id, std::uint64_t from_ns,
                   std::uint64_t to_ns);

/// The inserted samples of one transaction, folded per (boat, width, bucket) in memory and merged
/// into the tier table with one upsert per touched bucket.
///
/// Why not a trigger: an AFTER INSERT trigger upserts every tier row once per sample; at 1000
/// boats x 25 Hz that was 40-54 % of the writer's CPU (bench/store_bench.cpp). A 250 ms commit
/// touches one or two 1-s buckets and one 16-s bucket per boat, so the fold writes about a fifth
/// of the rows, each once.
///
/// Ties: within the fold and in the merge an extreme is replaced only by a strictly lower/higher
/// value, so of equal extremes the one inserted first is kept, whatever the chunking: folding
/// rows in insert order and merging the partial bucket into the stored one gives the same row as
/// merging them one by one.
class TierFold {
 public:
  TierFold() = default;
  // last_ points into open_: a copy would point into the other fold's map.
  TierFold(const TierFold&) = delete;
  TierFold& operator=(const TierFold&) = delete;

  /// One inserted sample (heading NaN: none).
  void add(const std::string& boat_id, std::uint64_t t_utc_ns, double heel_deg, double pitch_deg,
           double heading_deg);
  /// Merges every folded bucket into the tier table (inside the caller's transaction) and
  /// empties the fold.
  void write(sqlite3* db);
  /// Forgets what was folded (the transaction it belonged to rolled back).
  void clear();
  [[nodiscard]] std::size_t buckets() const { return open_.size(); }

 private:
  struct Extreme {
    std::uint64_t t_utc_ns = 0;
    double heel_deg = 0.0;
    double pitch_deg = 0.0;
    double heading_deg = 0.0;
  };
  struct Bucket {
    std::int64_t n = 0;
    std::array<Extreme, 4> e{};  // lowest heel, highest heel, lowest pitch, highest pitch
  };
  using Key = std::tuple<std::string, std::uint64_t, std::uint64_t>;  // boat, width_s, bucket
  std::map<Key, Bucket> open_;
  // The bucket each width touched last (open_.end(): none yet): samples come in time order per
  // boat, so nearly every sample lands in it and skips the map search. A map's end() stays
  // valid through inserts and clear().
  std::array<std::map<Key, Bucket>::iterator, 2> last_{open_.end(), open_.end()};
};

}  // namespace telltale::shore
