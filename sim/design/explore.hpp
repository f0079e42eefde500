// Design sweeps over the families, requirements (load sets with a safety factor), Pareto fronts.
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "sim/design/design.hpp"
#include "sim/design/families.hpp"

namespace ftstack::sim::design {

/// Loads a sensor must carry, with the safety factor on yield and buckling.
struct Requirement {
  std::string name;
  std::string note;  ///< where the figures come from
  std::shared_ptr<const LoadSet> loads;
  double safety_factor = 1.5;
  Vec6 peak = Vec6::Zero();  ///< |Fx| |Fy| |Fz| |Mx| |My| |Mz| the loads reach (for tables)
};

/// "panda-base" or "yumi-estop" (figures as issue 13 states them), else a JSON file:
/// {"name", "safety_factor", "cases": [[Fx,Fy,Fz,Mx,My,Mz], …]} and/or
/// "envelope": {"fxy_n", "fz_n", "mxy_nm", "mz_nm"}. Throws std::runtime_error naming
/// file:line:column.
[[nodiscard]] Requirement LoadRequirement(const std::string& name_or_path);
[[nodiscard]] Requirement ParseRequirement(const std::string& text, const std::string& origin);

/// How hard a design works under a requirement: each utilisation ≤ 1 passes.
struct RequirementCheck {
  double yield = 0;     ///< worst von Mises × SF / yield
  double gauge = 0;     ///< worst gauge strain / allowable (the loads stay inside the range)
  double buckling = 0;  ///< worst compression × SF / critical load
  [[nodiscard]] double worst() const { return std::max({yield, gauge, buckling}); }
  [[nodiscard]] bool met() const { return worst() <= 1.0; }
  [[nodiscard]] std::string binding() const;
};
[[nodiscard]] RequirementCheck Check(const DesignModel& m, const Requirement& r);

/// One evaluated design.
struct Candidate {
  std::string id;
  DesignModel model;
  DesignFigures figures;
  RequirementCheck check;
  bool pareto = false;
};

struct SweepOptions {
  DesignOptions design;
  Readout readout;
  double max_radius_m = 0;  ///< body envelope limit (rim / outermost leaf root), 0: none
  int hub_spoke_steps = 6;  ///< values per swept dimension
  int guided_steps = 5;
};

/// Evaluates both families over their parameter grids (progress lines to `progress`, may be null)
/// and marks the Pareto front (max tilt capacity, max force capacity, min force resolution,
/// max lateral stiffness).
[[nodiscard]] std::vector<Candidate> Sweep(const SweepOptions& o, const Requirement* req,
                                           std::ostream* progress);
void MarkPareto(std::vector<Candidate>* c);

/// Optimisation after the sweep: from the `starts` guided designs that meet `req` with the finest
/// force resolution, a coordinate search over the leaf dimensions (multiplicative steps halving
/// down to 1 %) minimising the force resolution while `req` stays met and the force range stays
/// ≤ kGoalForceRangeN (or, while it is above, minimising the force range). Appends the results
/// ("R…") and re-marks the Pareto front. Returns the number of evaluations.
int RefineGuided(std::vector<Candidate>* c, const Requirement& req, const SweepOptions& o,
                 int starts);

/// Prints the figures of one design with units.
void PrintDesign(std::ostream& out, const Candidate& c, const DesignOptions& o);
/// Prints the assumptions every figure rests on.
void PrintAssumptions(std::ostream& out, const DesignOptions& o, const Readout& r);
/// Prints the designs that meet `req` (best force resolution first), or for each family the
/// closest design and the constraint that binds, in numbers. Returns the number that meet it.
int PrintRequirementVerdict(std::ostream& out, const std::vector<Candidate>& c,
                            const Requirement& req, int max_listed);

/// The goal of issue 13: meets `req` (its safety factor at least 1.5) with a force range ≤ 500 N
/// and a noise-limited force resolution ≤ 0.1 N.
inline constexpr double kGoalForceRangeN = 500.0;
inline constexpr double kGoalForceResolutionN = 0.1;
[[nodiscard]] bool MeetsGoal(const Candidate& c, const Requirement& req);
/// Prints how many designs reach the goal and the best of them (or the nearest miss).
void PrintGoal(std::ostream& out, const std::vector<Candidate>& c, const Requirement& req);

}  // namespace ftstack::sim::design
