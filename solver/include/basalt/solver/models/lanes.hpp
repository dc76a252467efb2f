#pragma once
// The lane types: what a model's lane law (contact_lanes) reads and writes for many contacts at once, and the
// attribute its lane loops take. A model's scalar law (contact(), models/model.hpp's ContactKinematics and
// WallKinematics) and its lanes are written side by side in the model's header and compared on random inputs
// by a test (docs/ARCHITECTURE.md, "Scalar and lane laws"); the drivers batch the lanes through LanePass
// (interactions/lane_pass.hpp). Kept out of the model contract (model.hpp, contract.hpp), which only asks
// whether a model offers lanes.

namespace basalt::solver {

/// On a lane loop heavy in arithmetic: lets GCC use 512-bit vectors there where the target has them (it
/// prefers 256-bit ones elsewhere). The rotational bonds' lanes ran 0.76x the time with it and 16 lanes
/// (docs/validation-rock.md, "How fast"); other targets and compilers ignore it.
#if defined(__GNUC__) && !defined(__clang__) && (defined(__x86_64__) || defined(__i386__))
#define BASALT_WIDE_LANES [[gnu::target("prefer-vector-width=512")]]
#else
#define BASALT_WIDE_LANES
#endif

/// Contacts a pair driver evaluates side by side (Model::contact_lanes): 16 measured a little faster than 8
/// (and 4 or 64 slower) on the granular bench, docs/BENCHMARKS.md.
inline constexpr int kContactLaneWidth = 16;

/// W pairs in contact side by side (structure of arrays), for a velocity-dependent pair model that also
/// offers `template <bool Advance, class Real, int W> static void contact_lanes(const Coeffs<Real>&,
/// ContactLanes<Real, W, History>&)`: contact() for W pairs at once, written without branches so that the
/// compiler runs the lanes in vector registers. The driver fills the inputs (r2 = |x_i - x_j|^2, the rest
/// as in ContactKinematics; angular velocities zero when particles do not rotate) and h, and reads back the
/// outputs (the torques only when particles rotate) and, on real steps, h. A pair's result depends on its own
/// inputs only, never on its lane.
template <class Real, int W, class History>
struct ContactLanes {
  alignas(64) Real dx[W], dy[W], dz[W], r2[W], ri[W], rj[W], imi[W], imj[W], vx[W], vy[W], vz[W];
  alignas(64) Real wix[W], wiy[W], wiz[W], wjx[W], wjy[W], wjz[W];
  History h[W];
  alignas(64) Real fx[W], fy[W], fz[W], r[W];  ///< out: force on i (j gets the opposite), |x_i - x_j|
  alignas(64) Real tix[W], tiy[W], tiz[W];     ///< out: torque on i (force and couple about its centre)
  alignas(64) Real tjx[W], tjy[W], tjz[W];     ///< out: torque on j
  alignas(64) double dissipated[W];            ///< out, on real steps
  alignas(64) Real sliding[W];                 ///< out: 1 when the contact slides
  Real dt = 0;
};

/// W particles touching one planar wall side by side (structure of arrays), for a velocity-dependent wall
/// model that also offers `template <bool Advance, class Real, int W> static void contact_lanes(const
/// Coeffs<Real>&, WallLanes<Real, W, History>&)`: contact() for W particles at once, without branches. The
/// driver fills the inputs (as in WallKinematics; angular velocities zero when particles do not rotate) and
/// h, and reads back the outputs (the torque only when particles rotate) and, on real steps, h. A contact's
/// result depends on its own inputs only, never on its lane.
template <class Real, int W, class History>
struct WallLanes {
  alignas(64) Real d[W], r[W], im[W], vx[W], vy[W], vz[W], wx[W], wy[W], wz[W];
  History h[W];
  alignas(64) Real fx[W], fy[W], fz[W];  ///< out: force on the particle (the wall gets the opposite)
  alignas(64) Real tx[W], ty[W], tz[W];  ///< out: torque on the particle about its centre
  alignas(64) double dissipated[W];      ///< out, on real steps
  alignas(64) Real sliding[W];           ///< out: 1 when the contact slides
  Real nx = 0, ny = 0, nz = 0, dt = 0;   ///< the wall's unit normal, the time step
};

}  // namespace basalt::solver
