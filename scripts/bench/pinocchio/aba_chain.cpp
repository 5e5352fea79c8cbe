// Pinocchio's forward dynamics on camchain's scaling-study chains
// (codegen/tests/common/chain.rs: chain_ron(n) and planar_chain_ron(n)), for a side-by-side
// comparison with the project's generated code. Built and run by run.sh in this directory.
//
//   aba_chain BENCH_CSV CHECK_CSV CPU_CSV
//
// BENCH_CSV: family,n,aba_ns,crba_nle_ns,crba_nle_solve_ns (wall-clock ns per call, median of
//   31 batches, each batch >= 2 ms of calls cycling through 8 random states; the batches of
//   the three timed functions interleaved).
// CPU_CSV: the same columns from the same batches, timed by this thread's CPU time
//   (CLOCK_THREAD_CPUTIME_ID), which leaves out the time the thread was preempted: the
//   figure to use on a shared, loaded machine; equal to the wall clock on a quiet one.
// CHECK_CSV: the accelerations from aba at one fixed state, %.17g, for n in {4, 16, 64}.
//
// Models are built by hand with pinocchio::Model, the same physics as the RON text:
//   joint placement  SE3(identity, anchor)  (the body frame is the parent's frame moved to
//                    the anchor at q = 0, no constant rotation; axes are in the parent frame,
//                    which at q = 0 is the joint frame, so they carry over unchanged)
//   body inertia     Inertia(mass, com, I_c)  with I_c about the centre of mass, body axes
//   spring-damper    tau = -k q - c v  (Pinocchio has no joint springs; rest = 0)
// Unconstrained: the chain's tip contact belongs to the project's side only.

#include <pinocchio/multibody.hpp>
#include <pinocchio/spatial.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/cholesky.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <string>
#include <vector>

using pinocchio::Data;
using pinocchio::Inertia;
using pinocchio::JointIndex;
using pinocchio::Model;
using pinocchio::SE3;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

static const double kStiffness = 10.0; // every joint: spring 10, damper 0.5, rest 0
static const double kDamping = 0.5;

// The project's normalisation (model/src/schema/validate/fields.rs `unit`): each component
// divided by sqrt(x^2 + y^2 + z^2), summed in this order.
static Vector3d unit(double x, double y, double z)
{
  const double norm = std::sqrt(x * x + y * y + z * z);
  return Vector3d(x / norm, y / norm, z / norm);
}

// chain_ron(n): joints cycle revolute z, revolute y, prismatic along (0.8, 0.6, 0),
// revolute about (1, 1, 0); anchor (0, 0, 0.5) for body 0 and (0.2, 0, 0) for the others;
// mass 1 + 0.1 (i % 3); com (0.1, 0.01, -0.005); I_c = Diagonal(0.002, 0.003, 0.004);
// gravity (0, 0, -9.81).
static Model spatial_chain(int n)
{
  Model model;
  model.gravity = pinocchio::Motion(Vector3d(0.0, 0.0, -9.81), Vector3d::Zero());
  JointIndex parent = 0;
  for (int i = 0; i < n; ++i)
  {
    const Vector3d anchor = i == 0 ? Vector3d(0.0, 0.0, 0.5) : Vector3d(0.2, 0.0, 0.0);
    const SE3 placement(Matrix3d::Identity(), anchor);
    const std::string name = "q" + std::to_string(i);
    JointIndex joint = 0;
    switch (i % 4)
    {
    case 0:
      joint = model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
      break;
    case 1:
      joint = model.addJoint(parent, pinocchio::JointModelRY(), placement, name);
      break;
    case 2:
      joint = model.addJoint(
        parent, pinocchio::JointModelPrismaticUnaligned(unit(0.8, 0.6, 0.0)), placement, name);
      break;
    default:
      joint = model.addJoint(
        parent, pinocchio::JointModelRevoluteUnaligned(unit(1.0, 1.0, 0.0)), placement, name);
      break;
    }
    const double mass = 1.0 + 0.1 * double(i % 3);
    const Matrix3d inertia = Vector3d(0.002, 0.003, 0.004).asDiagonal();
    model.appendBodyToJoint(joint, Inertia(mass, Vector3d(0.1, 0.01, -0.005), inertia));
    parent = joint;
  }
  return model;
}

// planar_chain_ron(n): every joint revolute about z; anchor (0, 0, 0) for body 0 and
// (0.2, 0, 0) for the others; mass 1; com (0.1, 0, 0); I_c = Izz(0.003), which the model
// reads as a lamina in the body x-y plane (model/src/schema/raw.rs, validate/bodies.rs):
// diag(0.0015, 0.0015, 0.003); gravity (0, -9.81, 0).
static Model planar_chain(int n)
{
  Model model;
  model.gravity = pinocchio::Motion(Vector3d(0.0, -9.81, 0.0), Vector3d::Zero());
  JointIndex parent = 0;
  for (int i = 0; i < n; ++i)
  {
    const Vector3d anchor = i == 0 ? Vector3d(0.0, 0.0, 0.0) : Vector3d(0.2, 0.0, 0.0);
    const JointIndex joint = model.addJoint(
      parent, pinocchio::JointModelRZ(), SE3(Matrix3d::Identity(), anchor),
      "q" + std::to_string(i));
    const double izz = 0.003;
    const Matrix3d inertia = Vector3d(0.5 * izz, 0.5 * izz, izz).asDiagonal();
    model.appendBodyToJoint(joint, Inertia(1.0, Vector3d(0.1, 0.0, 0.0), inertia));
    parent = joint;
  }
  return model;
}

struct State
{
  VectorXd q, v, tau;
};

static VectorXd spring_tau(const VectorXd & q, const VectorXd & v)
{
  return -kStiffness * q - kDamping * v;
}

static volatile double g_sink = 0.0;

using Clock = std::chrono::steady_clock;

// One timed function: `calls` calls per batch cycling through the states, `calls` doubled
// from 8 until one batch takes >= 2 ms; ns per call of every batch.
struct Timed
{
  std::function<void(const State &)> call;
  long calls = 0;
  std::vector<double> per_call;     // wall clock (steady_clock), ns per call
  std::vector<double> per_call_cpu; // this thread's CPU time, ns per call
};

static double thread_cpu_ns()
{
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e9 * double(ts.tv_sec) + double(ts.tv_nsec);
}

// Runs one batch; returns its wall time in ns and stores its CPU time in `cpu`.
static double run_batch(const std::vector<State> & states, Timed & t, double & cpu)
{
  const std::size_t ns = states.size();
  const double c0 = thread_cpu_ns();
  const auto t0 = Clock::now();
  for (long k = 0; k < t.calls; ++k)
    t.call(states[std::size_t(k) % ns]);
  const auto t1 = Clock::now();
  cpu = thread_cpu_ns() - c0;
  return std::chrono::duration<double, std::nano>(t1 - t0).count();
}

// Median over 31 batches of ns per call for each function; the batches of the functions are
// interleaved (a, b, c, a, b, c, ...) so that a change of the machine's load during the run
// falls on all of them alike.
static void time_interleaved(const std::vector<State> & states, std::vector<Timed> & timed)
{
  double cpu = 0.0;
  for (Timed & t : timed)
  {
    t.calls = long(states.size());
    run_batch(states, t, cpu); // warm-up
    while (run_batch(states, t, cpu) < 2.0e6)
      t.calls *= 2;
  }
  for (int b = 0; b < 31; ++b)
    for (Timed & t : timed)
    {
      t.per_call.push_back(run_batch(states, t, cpu) / double(t.calls));
      t.per_call_cpu.push_back(cpu / double(t.calls));
    }
  for (Timed & t : timed)
  {
    std::sort(t.per_call.begin(), t.per_call.end());
    std::sort(t.per_call_cpu.begin(), t.per_call_cpu.end());
  }
}

static double median(const std::vector<double> & sorted)
{
  return sorted[sorted.size() / 2];
}

int main(int argc, char ** argv)
{
  if (argc != 4)
  {
    std::fprintf(stderr, "usage: %s BENCH_CSV CHECK_CSV CPU_CSV\n", argv[0]);
    return 2;
  }
  const char * families[2] = {"chain", "planar"};
  const int sizes[6] = {2, 4, 8, 16, 32, 64};

  // ---- correctness check: aba at q_i = 0.1 sin(i + 1), v_i = 0.2 cos(i + 1) ----
  FILE * check = std::fopen(argv[2], "w");
  if (!check)
  {
    std::perror(argv[2]);
    return 1;
  }
  std::fprintf(
    check, "# Pinocchio %s aba accelerations (ddq_0;ddq_1;...) at one state, i = 0..n-1:\n"
           "# q_i = 0.1*sin(i+1), v_i = 0.2*cos(i+1), tau_i = -10*q_i - 0.5*v_i\n"
           "# chain = chain_ron(n), planar = planar_chain_ron(n) "
           "(codegen/tests/common/chain.rs, no contact); %%.17g\n",
    PINOCCHIO_VERSION);
  std::fprintf(check, "family,n,ddq\n");
  double worst_solve_gap = 0.0;
  for (const char * family : families)
    for (int n : {4, 16, 64})
    {
      const Model model = std::string(family) == "chain" ? spatial_chain(n) : planar_chain(n);
      Data data(model);
      VectorXd q(n), v(n);
      for (int i = 0; i < n; ++i)
      {
        q[i] = 0.1 * std::sin(double(i + 1));
        v[i] = 0.2 * std::cos(double(i + 1));
      }
      const VectorXd tau = spring_tau(q, v);
      const VectorXd ddq = pinocchio::aba(model, data, q, v, tau);
      std::fprintf(check, "%s,%d,", family, n);
      for (int i = 0; i < n; ++i)
        std::fprintf(check, "%s%.17g", i ? ";" : "", ddq[i]);
      std::fprintf(check, "\n");
      // the same through crba + nonLinearEffects + Cholesky, as a consistency check
      pinocchio::crba(model, data, q);
      pinocchio::nonLinearEffects(model, data, q, v);
      pinocchio::cholesky::decompose(model, data);
      VectorXd x = tau - data.nle;
      pinocchio::cholesky::solve(model, data, x);
      worst_solve_gap =
        std::max(worst_solve_gap, (x - ddq).cwiseAbs().maxCoeff() / (1.0 + ddq.cwiseAbs().maxCoeff()));
    }
  std::fclose(check);
  std::fprintf(stderr, "aba vs crba+nle+cholesky: largest relative gap %.2e\n", worst_solve_gap);

  // ---- timings ----
  FILE * bench = std::fopen(argv[1], "w");
  FILE * bench_cpu = std::fopen(argv[3], "w");
  if (!bench || !bench_cpu)
  {
    std::perror(!bench ? argv[1] : argv[3]);
    return 1;
  }
  std::fprintf(bench, "family,n,aba_ns,crba_nle_ns,crba_nle_solve_ns\n");
  std::fprintf(bench_cpu, "family,n,aba_ns,crba_nle_ns,crba_nle_solve_ns\n");
  for (const char * family : families)
    for (int n : sizes)
    {
      const Model model = std::string(family) == "chain" ? spatial_chain(n) : planar_chain(n);
      Data data(model);
      std::mt19937_64 rng(20240611u + unsigned(n));
      std::uniform_real_distribution<double> uniform(-1.0, 1.0);
      std::vector<State> states(8);
      for (State & s : states)
      {
        s.q.resize(n);
        s.v.resize(n);
        for (int i = 0; i < n; ++i)
          s.q[i] = uniform(rng);
        for (int i = 0; i < n; ++i)
          s.v[i] = uniform(rng);
        s.tau = spring_tau(s.q, s.v); // precomputed: the timings exclude the spring forces
      }
      VectorXd x(n);

      std::vector<Timed> timed(3);
      timed[0].call = [&](const State & s) {
        pinocchio::aba(model, data, s.q, s.v, s.tau);
        g_sink = g_sink + data.ddq[n - 1];
      };
      timed[1].call = [&](const State & s) {
        pinocchio::crba(model, data, s.q);
        pinocchio::nonLinearEffects(model, data, s.q, s.v);
        g_sink = g_sink + data.M(0, n - 1) + data.nle[n - 1];
      };
      timed[2].call = [&](const State & s) {
        pinocchio::crba(model, data, s.q);
        pinocchio::nonLinearEffects(model, data, s.q, s.v);
        pinocchio::cholesky::decompose(model, data);
        x.noalias() = s.tau - data.nle;
        pinocchio::cholesky::solve(model, data, x);
        g_sink = g_sink + x[n - 1];
      };
      time_interleaved(states, timed);
      const double aba_ns = median(timed[0].per_call);
      const double crba_nle_ns = median(timed[1].per_call);
      const double solve_ns = median(timed[2].per_call);
      std::fprintf(
        bench, "%s,%d,%.1f,%.1f,%.1f\n", family, n, aba_ns, crba_nle_ns, solve_ns);
      std::fflush(bench);
      std::fprintf(
        bench_cpu, "%s,%d,%.1f,%.1f,%.1f\n", family, n, median(timed[0].per_call_cpu),
        median(timed[1].per_call_cpu), median(timed[2].per_call_cpu));
      std::fflush(bench_cpu);
      std::fprintf(
        stderr,
        "%s n=%d: aba %.1f ns, crba+nle %.1f ns, +solve %.1f ns  "
        "(CPU time: %.1f, %.1f, %.1f; fastest wall batch: %.1f, %.1f, %.1f)\n",
        family, n, aba_ns, crba_nle_ns, solve_ns, median(timed[0].per_call_cpu),
        median(timed[1].per_call_cpu), median(timed[2].per_call_cpu), timed[0].per_call[0],
        timed[1].per_call[0], timed[2].per_call[0]);
    }
  std::fclose(bench);
  std::fclose(bench_cpu);
  return 0;
}
