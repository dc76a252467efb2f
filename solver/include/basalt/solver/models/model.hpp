#pragma once
// What every model header declares, so that the registry (models/registry.hpp), the scene parser,
// `basalt-run --list-models` and the drivers can treat models alike (docs/ARCHITECTURE.md, "How to
// add a model"). A model is a struct of static members:
//
//   static constexpr std::string_view name;        // scene key value: type = "<name>"
//   static constexpr ModelKind kind;               // bond, pair or wall: which driver loops it
//   static constexpr std::string_view summary;     // one line: formula and source
//   static constexpr std::array<KeyDoc, N> keys;   // its scene keys
//   static constexpr Fields reads, writes;         // particle fields it uses (traits)
//   struct Params;                                 // parsed from the scene, double precision
//   template <class Real> struct Coeffs;           // Params prepared for the loop (what the driver keeps)
//   struct History;                                // per contact, empty when none (no storage then)
//   static Params parse(TableReader&);             // names the bad key in its error
//   template <class Real> static Coeffs<Real> coeffs(const Params&);
//   static double max_stiffness(const Params&, double rmax);   // for the critical time step
//   ... and the force law itself, whose signature depends on the kind (see the driver of that kind).
//
// The driver owns loops, Newton's third law, ghost ownership, energy tallies and history storage;
// the model is a pure function of its coefficients, its history and the pair's geometry.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

namespace basalt::solver {

/// Which driver loops a model: bonds, pairs in contact, planar walls, or a force on each particle
/// from its own state (body forces: gravity).
enum class ModelKind { bond, pair, wall, body };

constexpr std::string_view kind_name(ModelKind k) {
  return k == ModelKind::bond
             ? "bond"
             : (k == ModelKind::pair ? "pair" : (k == ModelKind::wall ? "wall" : "body force"));
}

/// One scene key of a model: its name and what it means (units, range, default).
struct KeyDoc {
  std::string_view key;
  std::string_view doc;
};

/// Particle fields (bit set), for a model's reads/writes traits and the scene's field list.
enum Fields : std::uint32_t {
  kNoFields = 0,
  kPosition = 1u << 0,
  kVelocity = 1u << 1,
  kForce = 1u << 2,
  kRadius = 1u << 3,
  kInverseMass = 1u << 4,
  kId = 1u << 5,
  kTag = 1u << 6,
};
constexpr Fields operator|(Fields a, Fields b) { return Fields(std::uint32_t(a) | std::uint32_t(b)); }

/// Bytes of per-contact history a model keeps (0 for an empty History: nothing is stored).
template <class Model>
constexpr std::size_t history_bytes() {
  return std::is_empty_v<typename Model::History> ? 0 : sizeof(typename Model::History);
}

/// A history entry is saved in checkpoints as float64 values: History must be made of doubles.
template <class Model>
constexpr std::size_t history_width() {
  static_assert(std::is_trivially_copyable_v<typename Model::History>, "a History is copied as bytes");
  static_assert(history_bytes<Model>() % sizeof(double) == 0, "a History holds doubles only");
  return history_bytes<Model>() / sizeof(double);
}

}  // namespace basalt::solver
