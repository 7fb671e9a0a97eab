// Pinocchio's C++ kernels timed per call, with no Python in the loop: the peer of benches/kernels_vs_pinocchio.py.
//
// Built by that script at run time (g++ -O3 -march=native against the headers and library the pip `pin` wheel
// ships; never committed as a binary) and driven over stdin/stdout so its repeats interleave with freefloat's in
// one run. The model arrives as a text file written from the very Pinocchio model the script checks against
// freefloat (joint by joint: parent, joint type, axis, placement in the parent, inertia), so both sides time the
// same tree; the states arrive as a binary file in Pinocchio's q/v layout.
//
// Commands (one per line), answers one line each:
//   load MODEL.txt STATES.bin   -> "ok K"            (K: index of the loaded model)
//   time K KERNEL CALLS         -> "WALL CPU SUM"    (seconds for CALLS calls cycling over the states; SUM keeps the
//                                                     work observable)
//   dump K KERNEL N OUT.bin     -> "ok"              (outputs of the first N states: crba the upper triangle
//                                                     mirrored, aba ddq, rnea tau; float64, state after state)
//   quit
// KERNEL is crba, aba or rnea.
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include <time.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace pin = pinocchio;

struct Case {
  pin::Model model;
  std::unique_ptr<pin::Data> data;
  int n = 0;
  std::vector<Eigen::VectorXd> q, v, t;
};

static double now(clockid_t c) {
  timespec ts;
  clock_gettime(c, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

static pin::Model read_model(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  pin::Model m;
  std::string tag;
  double g[3];
  in >> tag >> g[0] >> g[1] >> g[2];
  if (tag != "gravity") throw std::runtime_error(path + ": expected 'gravity'");
  m.gravity.linear(Eigen::Vector3d(g[0], g[1], g[2]));
  m.gravity.angular().setZero();
  int nj = 0;
  in >> tag >> nj;
  if (tag != "joints") throw std::runtime_error(path + ": expected 'joints'");
  for (int k = 0; k < nj; ++k) {
    int parent;
    std::string type;
    double a[3], r[9], p[3], mass, c[3], I[6];
    in >> tag >> parent >> type >> a[0] >> a[1] >> a[2];
    for (double &x : r) in >> x;
    for (double &x : p) in >> x;
    in >> mass >> c[0] >> c[1] >> c[2];
    for (double &x : I) in >> x;  // about the centre of mass: xx xy yy xz yz zz
    if (!in || tag != "joint") throw std::runtime_error(path + ": bad joint line " + std::to_string(k + 1));
    Eigen::Matrix3d R;
    R << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
    pin::SE3 X(R, Eigen::Vector3d(p[0], p[1], p[2]));
    Eigen::Vector3d axis(a[0], a[1], a[2]);
    pin::JointIndex id;
    const std::string name = "j" + std::to_string(k + 1);
    if (type == "JointModelFreeFlyer")
      id = m.addJoint(parent, pin::JointModelFreeFlyer(), X, name);
    else if (type == "JointModelRX")
      id = m.addJoint(parent, pin::JointModelRX(), X, name);
    else if (type == "JointModelRY")
      id = m.addJoint(parent, pin::JointModelRY(), X, name);
    else if (type == "JointModelRZ")
      id = m.addJoint(parent, pin::JointModelRZ(), X, name);
    else if (type == "JointModelPX")
      id = m.addJoint(parent, pin::JointModelPX(), X, name);
    else if (type == "JointModelPY")
      id = m.addJoint(parent, pin::JointModelPY(), X, name);
    else if (type == "JointModelPZ")
      id = m.addJoint(parent, pin::JointModelPZ(), X, name);
    else if (type == "JointModelRevoluteUnaligned")
      id = m.addJoint(parent, pin::JointModelRevoluteUnaligned(axis), X, name);
    else if (type == "JointModelPrismaticUnaligned")
      id = m.addJoint(parent, pin::JointModelPrismaticUnaligned(axis), X, name);
    else
      throw std::runtime_error(path + ": joint type " + type + " is not handled by this peer");
    Eigen::Matrix3d Ic;
    Ic << I[0], I[1], I[3], I[1], I[2], I[4], I[3], I[4], I[5];
    m.appendBodyToJoint(id, pin::Inertia(mass, Eigen::Vector3d(c[0], c[1], c[2]), Ic), pin::SE3::Identity());
  }
  return m;
}

static void read_states(const std::string &path, Case &cs) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  double hdr[3];
  in.read(reinterpret_cast<char *>(hdr), sizeof hdr);
  const int nq = int(hdr[0]), nv = int(hdr[1]);
  cs.n = int(hdr[2]);
  if (nq != cs.model.nq || nv != cs.model.nv)
    throw std::runtime_error(path + ": states do not match the model's nq/nv");
  auto block = [&](std::vector<Eigen::VectorXd> &out, int dim) {
    out.assign(cs.n, Eigen::VectorXd(dim));
    for (auto &x : out) in.read(reinterpret_cast<char *>(x.data()), sizeof(double) * dim);
  };
  block(cs.q, nq);
  block(cs.v, nv);
  block(cs.t, nv);
  if (!in) throw std::runtime_error(path + ": file too short");
}

// One call of the kernel on state k; returns one number of its output so the loop cannot be dropped.
static inline double run(Case &cs, const std::string &kernel, int k) {
  pin::Data &d = *cs.data;
  if (kernel == "crba") return pin::crba(cs.model, d, cs.q[k])(0, 0);
  if (kernel == "aba") return pin::aba(cs.model, d, cs.q[k], cs.v[k], cs.t[k])[0];
  if (kernel == "rnea") return pin::rnea(cs.model, d, cs.q[k], cs.v[k], cs.t[k])[0];
  throw std::runtime_error("unknown kernel " + kernel);
}

template <class F>
static void timed(Case &cs, long calls, F f, double &wall, double &cpu, double &sum) {
  const double w0 = now(CLOCK_MONOTONIC), c0 = now(CLOCK_PROCESS_CPUTIME_ID);
  int k = 0;
  for (long c = 0; c < calls; ++c) {
    sum += f(k);
    if (++k == cs.n) k = 0;
  }
  wall = now(CLOCK_MONOTONIC) - w0;
  cpu = now(CLOCK_PROCESS_CPUTIME_ID) - c0;
}

int main() {
  std::vector<std::unique_ptr<Case>> cases;
  std::string line;
  std::cout.precision(17);
  while (std::getline(std::cin, line)) {
    std::istringstream cmd(line);
    std::string op;
    cmd >> op;
    try {
      if (op == "quit") break;
      if (op == "load") {
        std::string mp, sp;
        cmd >> mp >> sp;
        auto cs = std::make_unique<Case>();
        cs->model = read_model(mp);
        cs->data = std::make_unique<pin::Data>(cs->model);
        read_states(sp, *cs);
        cases.push_back(std::move(cs));
        std::cout << "ok " << cases.size() - 1 << std::endl;
      } else if (op == "time") {
        size_t k;
        std::string kernel;
        long calls;
        cmd >> k >> kernel >> calls;
        if (!cmd || k >= cases.size()) throw std::runtime_error("bad time command: " + line);
        Case &cs = *cases[k];
        double wall, cpu, sum = 0;
        pin::Data &d = *cs.data;
        // the kernel is chosen outside the timed loop: the loop body is the bare library call
        if (kernel == "crba")
          timed(cs, calls, [&](int i) { return pin::crba(cs.model, d, cs.q[i])(0, 0); }, wall, cpu, sum);
        else if (kernel == "aba")
          timed(cs, calls, [&](int i) { return pin::aba(cs.model, d, cs.q[i], cs.v[i], cs.t[i])[0]; }, wall, cpu,
                sum);
        else if (kernel == "rnea")
          timed(cs, calls, [&](int i) { return pin::rnea(cs.model, d, cs.q[i], cs.v[i], cs.t[i])[0]; }, wall,
                cpu, sum);
        else
          throw std::runtime_error("unknown kernel " + kernel);
        std::cout << wall << " " << cpu << " " << sum << std::endl;
      } else if (op == "dump") {
        size_t k;
        std::string kernel, out;
        int n;
        cmd >> k >> kernel >> n >> out;
        if (!cmd || k >= cases.size()) throw std::runtime_error("bad dump command: " + line);
        Case &cs = *cases[k];
        std::ofstream o(out, std::ios::binary);
        for (int i = 0; i < n && i < cs.n; ++i) {
          run(cs, kernel, i);
          Eigen::MatrixXd r;
          if (kernel == "crba") {
            r = cs.data->M;
            r.triangularView<Eigen::StrictlyLower>() = r.transpose().triangularView<Eigen::StrictlyLower>();
          } else if (kernel == "aba") {
            r = cs.data->ddq;
          } else {
            r = cs.data->tau;
          }
          o.write(reinterpret_cast<const char *>(r.data()), sizeof(double) * r.size());
        }
        o.close();  // flushed before the answer, which the driver takes as "the file is complete"
        if (!o) throw std::runtime_error("cannot write " + out);
        std::cout << "ok" << std::endl;
      } else {
        throw std::runtime_error("unknown command: " + line);
      }
    } catch (const std::exception &e) {
      std::cout << "error " << e.what() << std::endl;
    }
  }
  return 0;
}
