#include "road_users/mobil.h"

namespace convoy::road_users {

MobilDecision decide_lane_change(const Idm& idm, const Mobil& mobil, double v, double v0_here,
                                 double length, const LaneNeighbours& current,
                                 const LaneNeighbours& target) {
  const LaneNeighbour& cl = current.leader;
  const LaneNeighbour& cf = current.follower;
  const LaneNeighbour& nl = target.leader;
  const LaneNeighbour& nf = target.follower;
  if (nl.found && nl.gap < 0) return {LaneChange::kBlocked, 0};
  if (nf.found && nf.gap < 0) return {LaneChange::kBlocked, 0};
  const double a_c = idm.accel(v, cl.gap, cl.speed, v0_here);
  const double a_c2 = idm.accel(v, nl.gap, nl.speed, v0_here);
  // New follower: now behind the new leader, then behind the driver.
  double a_n = 0, a_n2 = 0;
  if (nf.found) {
    const double gap_now = nl.found ? nl.gap + nf.gap + length : INFINITY;
    a_n = idm.accel(nf.speed, gap_now, nl.speed, idm.v0);
    a_n2 = idm.accel(nf.speed, nf.gap, v, idm.v0);
    if (a_n2 < -mobil.b_safe) return {LaneChange::kUnsafe, 0};
  }
  // Old follower: now behind the driver, then behind the old leader.
  double a_o = 0, a_o2 = 0;
  if (cf.found) {
    a_o = idm.accel(cf.speed, cf.gap, v, idm.v0);
    a_o2 = idm.accel(cf.speed, cl.found ? cl.gap + cf.gap + length : INFINITY, cl.speed, idm.v0);
  }
  const double incentive = a_c2 - a_c + mobil.politeness * ((a_n2 - a_n) + (a_o2 - a_o));
  return {incentive <= mobil.threshold ? LaneChange::kNotWorth : LaneChange::kChange, incentive};
}

}  // namespace convoy::road_users
