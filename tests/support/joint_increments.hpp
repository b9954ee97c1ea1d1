#pragma once
// The check of a joint's StepIncrement (joints/joint.hpp): the child's increment over a step,
// composed from the parent's without subtracting rounded coordinates, is the update less the
// start, and it does not change when the whole configuration is moved far from the origin, where
// the difference of the rounded coordinates loses ε × the distance (docs/theory/schemes.md §7).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "isoflex/joints/joint.hpp"
#include "isoflex/math/rotation.hpp"
#include "support/finite_difference.hpp"

namespace isoflex::test {

struct JointIncrementErrors {
  double consistency = 0.0;  // |dq − (q_B,n+1 − q_B,n)|∞ and |dQ − (Q_B − I)|∞, at the start given
  double invariance = 0.0;             // |dq(moved by `offset`) − dq|∞
  double difference_invariance = 0.0;  // the same of q_B,n+1 − q_B,n (what the increment avoids)
  bool moves = false;  // the child's position moves (a pinned support's does not, bit for bit)
};

// One step of `j` from (qa_n, qb_n): the parent (the ground if `ground_parent`: it stays) moves
// by a random translation and rotation of about `size`, the joint by random increments of about
// `size`; then the same with every node but the ground moved by `offset` along (1, 1, 1).
inline JointIncrementErrors joint_increment_errors(const joints::Joint& j, const VecX& qa_n,
                                                   const VecX& qb_n, bool ground_parent,
                                                   double offset, double size, std::mt19937& g) {
  Mat3 dQ = Mat3::Zero();
  const Mat3 QA = ground_parent ? Mat3::Identity() : rodrigues(random_vector(g, 3, size), dQ);
  const Vec3 dphi = ground_parent ? Vec3::Zero() : Vec3(random_vector(g, 3, size));
  const VecX tau = random_vector(g, j.freedom_count(), size);
  struct Step {
    joints::StepIncrement child;
    VecX difference;
    Mat3 rotation;
  };
  const auto step = [&](double shift) {
    VecX qa = qa_n, qb = qb_n;
    if (!ground_parent) qa.head<3>().array() += shift;
    qb.head<3>().array() += shift;
    joints::StepIncrement parent;
    parent.dq = NodeVec::Zero(qa.size());
    parent.dq.head<3>() = dphi;
    parent.dQ = dQ;
    VecX qa1 = qa;
    qa1.head<3>() += dphi;
    for (int i = 3; i < qa.size(); i += 3) {  // every director (frame or director node) turns
      qa1.segment<3>(i) = QA * qa.segment<3>(i);
      parent.dq.segment<3>(i) = dQ * qa.segment<3>(i);
    }
    Step s;
    const VecX qb1 = j.update(qa, qa1, QA, qb, tau, &s.rotation, &parent, &s.child);
    s.difference = qb1 - qb;
    return s;
  };
  const Step near = step(0.0), far = step(offset);
  JointIncrementErrors e;
  e.consistency =
      std::max((near.child.dq - near.difference).lpNorm<Eigen::Infinity>(),
               (near.child.dQ - (near.rotation - Mat3::Identity())).lpNorm<Eigen::Infinity>());
  e.invariance = (far.child.dq - near.child.dq).lpNorm<Eigen::Infinity>();
  e.difference_invariance = (far.difference - near.difference).lpNorm<Eigen::Infinity>();
  e.moves = near.child.dq.head<3>().lpNorm<Eigen::Infinity>() > 0.0;
  return e;
}

// Five random steps of 0.02 from (qa_n, qb_n): the increment is the update less the start (to
// q_B,n+1's own rounding, coordinates up to ~4), within `invariance` of itself 10⁶ m away, where
// the difference of the rounded coordinates is off by more than 10⁻¹¹ (if the child moves).
inline void expect_increments_without_cancellation(const joints::Joint& j, const VecX& qa_n,
                                                   const VecX& qb_n, bool ground_parent,
                                                   double invariance, std::mt19937& g) {
  for (int k = 0; k < 5; ++k) {
    const JointIncrementErrors e =
        joint_increment_errors(j, qa_n, qb_n, ground_parent, 1e6, 0.02, g);
    EXPECT_LT(e.consistency, 3e-15);
    EXPECT_LT(e.invariance, invariance);
    if (e.moves) {
      EXPECT_GT(e.difference_invariance, 1e-11);  // what the increment avoids
    }
  }
}

}  // namespace isoflex::test
