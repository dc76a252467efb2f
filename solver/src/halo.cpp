#include "basalt/solver/parallel/halo.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>

namespace basalt::solver {

namespace {

struct BondRecord {
  std::int64_t a, b;
  double r0;
  std::int32_t group;
  std::int32_t pad;
};

/// Sends `out` to dest and receives from src (either may be MPI_PROC_NULL).
template <class T>
std::vector<T> sendrecv(MPI_Comm comm, const std::vector<T>& out, int dest, int src) {
  long long n_out = static_cast<long long>(out.size()), n_in = 0;
  MPI_Sendrecv(&n_out, 1, MPI_LONG_LONG, dest, 11, &n_in, 1, MPI_LONG_LONG, src, 11, comm, MPI_STATUS_IGNORE);
  std::vector<T> in(static_cast<std::size_t>(n_in));
  MPI_Sendrecv(out.data(), static_cast<int>(out.size() * sizeof(T)), MPI_BYTE, dest, 12, in.data(),
               static_cast<int>(in.size() * sizeof(T)), MPI_BYTE, src, 12, comm, MPI_STATUS_IGNORE);
  return in;
}

/// A ghost refresh travels array by array (all x, then all y, ...: step_arrays() order), so that
/// packing is one gather per array and unpacking one contiguous copy per array into the ghosts'
/// range [begin, begin + n), instead of an indirect load and store per value and particle through
/// the 9 or 13 arrays of a rotating scene (its time gain was within the noise: docs/BENCHMARKS.md).
template <class Real, class Arrays>
void pack_step(std::vector<Real>& buf, const Arrays& arrays, std::size_t na,
               const std::vector<std::int32_t>& list) {
  const std::size_t n = list.size();
  buf.resize(na * n);
  for (std::size_t a = 0; a < na; ++a) {
    const Real* src = arrays[a]->data();
    Real* dst = buf.data() + a * n;
    for (std::size_t k = 0; k < n; ++k) dst[k] = src[list[k]];
  }
}

template <class Real, class Arrays>
void unpack_step(const std::vector<Real>& buf, const Arrays& arrays, std::size_t na, std::size_t begin,
                 std::size_t n) {
  for (std::size_t a = 0; a < na; ++a) std::copy_n(buf.data() + a * n, n, arrays[a]->data() + begin);
}

template <class Real>
const std::vector<Real>& axis(const Particles<Real>& p, int d) {
  return d == 0 ? p.x : (d == 1 ? p.y : p.z);
}

/// After migration: keeps each bond once, and only while one of its ends is owned here. Only a bond
/// that touches a particle that left or arrived (every bond that arrived does) can change on either
/// count, so only those are examined: the cost follows the migrants, not the bond count (a sort of
/// all bonds here was 20 % of a 2-rank rebuild). The order of the bonds kept needs no care:
/// resolve_bonds() makes it canonical.
template <class Real>
void settle_bonds(const Particles<Real>& p, Bonds<Real>& bonds, std::vector<std::int64_t>& migrants) {
  if (migrants.empty()) return;
  std::sort(migrants.begin(), migrants.end());
  const auto migrant = [&](std::int64_t id) {
    return std::binary_search(migrants.begin(), migrants.end(), id);
  };
  std::vector<std::uint32_t> keep, touched;
  keep.reserve(bonds.size());
  std::vector<std::int64_t> ends;  // of the touched bonds
  for (std::uint32_t k = 0; k < bonds.size(); ++k) {
    if (!migrant(bonds.a[k]) && !migrant(bonds.b[k])) {
      keep.push_back(k);
      continue;
    }
    touched.push_back(k);
    ends.push_back(bonds.a[k]);
    ends.push_back(bonds.b[k]);
  }
  std::sort(ends.begin(), ends.end());
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  const auto end_index = [&](std::int64_t id) {
    return static_cast<std::size_t>(std::lower_bound(ends.begin(), ends.end(), id) - ends.begin());
  };
  std::vector<char> owned(ends.size() + 1, 0);  // which ends are owned here now (no ghosts yet)
  for (std::size_t i = 0; i < p.n_owned; ++i) {
    const auto e = end_index(p.id[i]);
    if (e < ends.size() && ends[e] == p.id[i]) owned[e] = 1;
  }
  const auto lo = [&](std::uint32_t k) { return std::min(bonds.a[k], bonds.b[k]); };
  const auto hi = [&](std::uint32_t k) { return std::max(bonds.a[k], bonds.b[k]); };
  std::sort(touched.begin(), touched.end(), [&](std::uint32_t i, std::uint32_t j) {
    return lo(i) != lo(j) ? lo(i) < lo(j) : (hi(i) != hi(j) ? hi(i) < hi(j) : i < j);
  });
  for (std::size_t t = 0; t < touched.size(); ++t) {
    const auto k = touched[t];
    if (t > 0 && lo(touched[t - 1]) == lo(k) && hi(touched[t - 1]) == hi(k)) continue;  // a copy
    if (owned[end_index(bonds.a[k])] || owned[end_index(bonds.b[k])]) keep.push_back(k);
  }
  bonds.ia.clear();
  bonds.ib.clear();
  bonds.permute(keep);
}

/// Copies the contact-history records that name a particle leaving to either side (ids sorted) to that
/// side's neighbour, and appends what the neighbours send. Records stay here too: the pair may still
/// be listed here (its other end owned here) and the next rebuild takes each pair's record by its ids.
void send_history(MPI_Comm comm, ContactRecords& h, const std::array<std::vector<std::int64_t>, 2>& leaving,
                  int lo_rank, int hi_rank) {
  for (int side = 0; side < 2; ++side) {
    const auto& ids = leaving[side];
    ContactRecords out;
    out.width = h.width;
    if (!ids.empty())
      for (std::size_t k = 0; k < h.size(); ++k)
        if (std::binary_search(ids.begin(), ids.end(), h.a[k]) ||
            std::binary_search(ids.begin(), ids.end(), h.b[k]))
          out.push(h.a[k], h.b[k], h.at(k));
    const int dest = side == 0 ? lo_rank : hi_rank, src = side == 0 ? hi_rank : lo_rank;
    const auto a = sendrecv(comm, out.a, dest, src);
    const auto b = sendrecv(comm, out.b, dest, src);
    const auto v = sendrecv(comm, out.values, dest, src);
    h.a.insert(h.a.end(), a.begin(), a.end());
    h.b.insert(h.b.end(), b.begin(), b.end());
    h.values.insert(h.values.end(), v.begin(), v.end());
  }
}

}  // namespace

template <class Real>
std::optional<std::string> Halo<Real>::migrate(Particles<Real>& p, Bonds<Real>& bonds,
                                               const std::vector<ContactRecords*>& history, bool far) {
  const MPI_Comm comm = dec_.comm().raw();
  std::optional<std::string> error;
  std::vector<std::int64_t> migrants;  // ids that left or arrived here
  const std::size_t record = p.record_bytes(false);
  for (int d = 0; d < 3; ++d) {
    if (dec_.dims()[d] == 1) continue;
    // far: a particle that arrived outside this rank's slab goes on along the same axis in the next
    // round (one hop per round), until no rank has such a particle.
    for (bool again = true; again;) {
      std::size_t outside = 0;
      const auto& c = axis(p, d);
      std::array<std::vector<std::byte>, 2> out;
      std::array<std::vector<std::int64_t>, 2> leaving_ids;
      std::vector<std::size_t> leaving;
      for (std::size_t i = 0; i < p.n_owned; ++i) {
        const int side = c[i] < dec_.lo(d) ? 0 : (c[i] >= dec_.hi(d) ? 1 : -1);
        if (side < 0) continue;
        p.pack(i, false, out[side]);
        leaving_ids[side].push_back(p.id[i]);
        leaving.push_back(i);
      }
      std::array<std::vector<BondRecord>, 2> bout;
      for (int side = 0; side < 2; ++side) {
        auto& ids = leaving_ids[side];
        if (ids.empty()) continue;
        std::sort(ids.begin(), ids.end());
        for (std::size_t k = 0; k < bonds.size(); ++k)
          if (std::binary_search(ids.begin(), ids.end(), bonds.a[k]) ||
              std::binary_search(ids.begin(), ids.end(), bonds.b[k]))
            bout[side].push_back(
                BondRecord{bonds.a[k], bonds.b[k], double(bonds.r0[k]), bonds.group_of(k), 0});
      }
      for (auto* h : history)
        if (h) send_history(comm, *h, leaving_ids, dec_.neighbor(d, 0), dec_.neighbor(d, 1));
      for (auto it = leaving.rbegin(); it != leaving.rend(); ++it) p.swap_remove_owned(*it);
      for (const auto& ids : leaving_ids) migrants.insert(migrants.end(), ids.begin(), ids.end());

      for (int side = 0; side < 2; ++side) {
        const int dest = dec_.neighbor(d, side), src = dec_.neighbor(d, 1 - side);
        const auto in = sendrecv(comm, out[side], dest, src);
        const auto bin = sendrecv(comm, bout[side], dest, src);
        p.make_room(p.n_owned + in.size() / record, p.size() + in.size() / record);
        for (std::size_t at = 0; at < in.size(); at += record) {
          p.unpack(in.data() + at, false);
          const std::size_t i = p.n_owned - 1;
          migrants.push_back(p.id[i]);
          const double v = double(axis(p, d)[i]);
          if (v >= dec_.lo(d) && v < dec_.hi(d)) continue;
          ++outside;
          if (!far && !error)
            error = fmt::format(
                "particle id {} at ({}, {}, {}) moved more than one rank's region between two neighbour-list "
                "rebuilds (arrived at rank {} owning [{}, {}) along axis {})",
                p.id[i], p.x[i], p.y[i], p.z[i], dec_.comm().rank(), dec_.lo(d), dec_.hi(d), "xyz"[d]);
        }
        for (const auto& b : bin) bonds.push(b.a, b.b, Real(b.r0), static_cast<std::uint8_t>(b.group));
      }
      again = far && dec_.comm().max(double(outside)) > 0;
    }
  }
  settle_bonds(p, bonds, migrants);
  return error;
}

template <class Real>
void Halo<Real>::build_ghosts(Particles<Real>& p, double width) {
  const MPI_Comm comm = dec_.comm().raw();
  const std::size_t record = p.record_bytes(true);
  for (int d = 0; d < 3; ++d) {
    for (int side = 0; side < 2; ++side) {
      send_[d][side].clear();
      recv_count_[d][side] = 0;
      recv_begin_[d][side] = p.size();
    }
    if (dec_.dims()[d] == 1) continue;
    const auto& c = axis(p, d);
    const std::size_t n = p.size();
    const double lo = dec_.lo(d) + width, hi = dec_.hi(d) - width;
    const bool has_lo = dec_.neighbor(d, 0) != MPI_PROC_NULL, has_hi = dec_.neighbor(d, 1) != MPI_PROC_NULL;
    for (std::size_t i = 0; i < n; ++i) {
      if (has_lo && c[i] < lo) send_[d][0].push_back(static_cast<std::int32_t>(i));
      if (has_hi && c[i] >= hi) send_[d][1].push_back(static_cast<std::int32_t>(i));
    }
    for (int side = 0; side < 2; ++side) {
      std::vector<std::byte> out;
      out.reserve(send_[d][side].size() * record);
      for (auto i : send_[d][side]) p.pack(static_cast<std::size_t>(i), true, out);
      // Sending to side s means receiving from the other side.
      const auto in = sendrecv(comm, out, dec_.neighbor(d, side), dec_.neighbor(d, 1 - side));
      recv_begin_[d][1 - side] = p.size();
      recv_count_[d][1 - side] = in.size() / record;
      p.make_room(p.n_owned, p.size() + in.size() / record);
      for (std::size_t at = 0; at < in.size(); at += record) p.unpack(in.data() + at, true);
    }
  }
}

template <class Real>
void Halo<Real>::begin_update_ghosts(Particles<Real>& p) {
  const MPI_Comm comm = dec_.comm().raw();
  const MPI_Datatype type = sizeof(Real) == sizeof(double) ? MPI_DOUBLE : MPI_FLOAT;
  const auto [arrays, na] = Particles<Real>::step_arrays(p);
  int last = -1;
  for (int d = 0; d < 3; ++d)
    if (dec_.dims()[d] > 1) last = d;
  async_axis_ = last;
  for (int d = 0; d <= last; ++d) {
    if (dec_.dims()[d] == 1) continue;
    for (int side = 0; side < 2; ++side) {
      const auto& list = send_[d][side];
      auto& sbuf = d == last ? async_send_[side] : sbuf_;
      auto& rbuf = d == last ? async_recv_[side] : rbuf_;
      pack_step(sbuf, arrays, na, list);
      const std::size_t nin = recv_count_[d][1 - side], begin = recv_begin_[d][1 - side];
      rbuf.resize(na * nin);
      const int dest = dec_.neighbor(d, side), src = dec_.neighbor(d, 1 - side);
      if (d == last) {
        MPI_Irecv(rbuf.data(), static_cast<int>(rbuf.size()), type, src, 21 + side, comm,
                  &requests_[2 * side]);
        MPI_Isend(sbuf.data(), static_cast<int>(sbuf.size()), type, dest, 21 + side, comm,
                  &requests_[2 * side + 1]);
        continue;
      }
      MPI_Sendrecv(sbuf.data(), static_cast<int>(sbuf.size()), type, dest, 21, rbuf.data(),
                   static_cast<int>(rbuf.size()), type, src, 21, comm, MPI_STATUS_IGNORE);
      unpack_step(rbuf, arrays, na, begin, nin);
    }
  }
}

template <class Real>
void Halo<Real>::progress_ghosts() {
  if (async_axis_ < 0) return;
  int done = 0;
  MPI_Testall(4, requests_.data(), &done, MPI_STATUSES_IGNORE);
}

template <class Real>
void Halo<Real>::end_update_ghosts(Particles<Real>& p) {
  const int d = async_axis_;
  if (d < 0) return;
  MPI_Waitall(4, requests_.data(), MPI_STATUSES_IGNORE);
  const auto [arrays, na] = Particles<Real>::step_arrays(p);
  for (int side = 0; side < 2; ++side) {
    const std::size_t nin = recv_count_[d][1 - side], begin = recv_begin_[d][1 - side];
    unpack_step(async_recv_[side], arrays, na, begin, nin);
  }
  async_axis_ = -1;
}

template <class Real>
std::size_t Halo<Real>::memory_bytes() const {
  std::size_t b = (sbuf_.capacity() + rbuf_.capacity()) * sizeof(Real);
  for (int side = 0; side < 2; ++side)
    b += (async_send_[side].capacity() + async_recv_[side].capacity()) * sizeof(Real);
  for (const auto& a : send_)
    for (const auto& s : a) b += s.capacity() * sizeof(std::int32_t);
  return b;
}

template class Halo<double>;
template class Halo<float>;

}  // namespace basalt::solver
