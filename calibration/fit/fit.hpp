// Fitting a calibration from rig data: affine, temperature and second-order models, chosen by
// cross-validation over whole load directions (or load blocks), with ridge regularisation.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "firmware/fixed_calibration.hpp"
#include "measurement/recording.hpp"
#include "measurement/wrench.hpp"

namespace ftstack::cal {

/// How rows are grouped into load blocks (the unit that cross-validation holds out).
struct BlockOptions {
  /// Per-axis scale of the wrench for hold detection (N, N·m); 0 → the largest |load| seen.
  std::array<double, 6> scale{};
  /// A hold ends when any axis moves more than this fraction of its scale from the hold's start.
  double hold_tolerance = 0.01;
  /// A hold needs at least this many rows, and at least a fifth of the N50 run length (runs at
  /// least that long cover half the rows), so a slow ramp's short runs stay transitions.
  std::size_t min_hold_rows = 5;
  /// Without holds (continuous loading): this many contiguous chunks of equal length.
  std::size_t continuous_blocks = 20;
};

/// Rig data ready for fitting: bridges, reference wrench, temperature and block of every row.
struct RigData {
  std::string path;
  Eigen::MatrixXd bridges;  ///< rows × N, input unit (mV/V)
  Eigen::MatrixXd wrench;   ///< rows × 6, N and N·m
  Eigen::VectorXd temp_c;   ///< rows, °C; empty without a temp_C column
  std::vector<double> t_s;  ///< time of every row, s
  std::vector<int> block;   ///< block of every row, 0 … block_count − 1 (in order of first row)
  int block_count = 0;
  std::string block_method;  ///< how blocks were found ("column pose", "holds", "chunks")
  /// Validation group of every row (0 … group_count − 1): what a new use differs in — the robot
  /// orientation or load direction. Whole blocks always share a group.
  std::vector<int> group;
  int group_count = 0;
  std::string group_method;  ///< "column group" or "load direction within 5°"
};

/// Groups blocks by the direction of their mean load: the force direction where the block's
/// force is at least 10 % of the largest block force (a mass held in one orientation gives one
/// direction whatever its size or lever), else the direction of the moment (each axis divided by
/// its scale); unloaded blocks (every axis within 2 % of scale) form one group. Directions within
/// `tolerance_deg` of a group's first block join it. Returns the group of every block.
[[nodiscard]] std::vector<int> GroupBlocksByLoadDirection(const Eigen::MatrixXd& wrench,
                                                          const std::vector<int>& block,
                                                          int block_count,
                                                          const std::array<double, 6>& scale,
                                                          double tolerance_deg, int* group_count);

/// Groups rows into blocks. A `block` or `pose` column wins (rows with equal values form one
/// block, wherever they are); otherwise static holds are detected from the reference wrench
/// (long runs of rows within hold_tolerance of the run's first row, see BlockOptions) and every
/// transition row joins the nearest hold in time; with fewer than two holds covering < 30 % of
/// the rows the recording is treated as continuous loading and cut into contiguous chunks.
[[nodiscard]] std::vector<int> DetectBlocks(const Eigen::MatrixXd& wrench,
                                            const BlockOptions& options, int* block_count,
                                            std::string* method);

/// Temperature levels of a rig that holds temperatures: rows sorted by temperature, a new level
/// where the gap to the next warmer row exceeds `gap_c` (°C). Returns the level of every row
/// (0 = coldest) and their number in *count (0 for an empty column).
[[nodiscard]] std::vector<int> TemperatureLevels(const Eigen::VectorXd& temp_c, double gap_c,
                                                 int* count);

/// Reads the columns a fit needs (b0…, Fx…Mz, optional temp_C, block/pose, group) and finds
/// blocks and validation groups (a `group` column wins; otherwise GroupBlocksByLoadDirection
/// with 5°; a block whose rows carry two group values is refused).
/// Throws RecordingError naming the file when columns are missing or N is not 1 … 8.
[[nodiscard]] RigData RigDataFromRecording(const Recording& rec, const BlockOptions& options);

/// Calibration model families.
enum class ModelKind {
  kLinear = 0,     ///< affine: offsets + 6 × N matrix
  kLinearTemp,     ///< affine + per-channel bias and gain slopes against temperature
  kQuadratic,      ///< affine + all products of two channels
  kQuadraticTemp,  ///< both
  kQuadraticDiag,  ///< affine + the square of every channel (no cross products)
};
[[nodiscard]] const char* ToString(ModelKind kind);
/// "linear", "linear-temp", "quadratic", "quadratic-temp", "quadratic-diag"; nullopt otherwise.
[[nodiscard]] std::optional<ModelKind> ParseModelKind(const std::string& name);

struct FitOptions {
  std::vector<ModelKind> models;  ///< candidates; empty → every model the data supports
  /// Ridge strengths tried, relative to the standardised features (0 = plain least squares):
  /// below 1e-4 a few points, then 1, 2, 3, 5 per decade up to 1, so that no step exceeds ×2
  /// and the choice can land between the points of a coarser grid.
  std::vector<double> lambdas = {0.0,  1e-9, 1e-7, 1e-5, 1e-4, 2e-4, 3e-4, 5e-4, 1e-3, 2e-3, 3e-3,
                                 5e-3, 0.01, 0.02, 0.03, 0.05, 0.1,  0.2,  0.3,  0.5,  1.0};
  /// Cross-validation folds, ≤ number of validation units. Unit g goes to fold g mod folds, so
  /// with no more units than folds every unit is held out alone.
  int folds = 10;
  /// Hold out whole validation groups (load directions; the default when there are at least
  /// three), or whole blocks (holds).
  bool by_group = true;
  std::array<double, 6> rated{};  ///< rated range per axis; 0 → the largest |load| in the data
};

/// Cross-validated score of one (model, λ) candidate.
struct CandidateScore {
  ModelKind kind = ModelKind::kLinear;
  double lambda = 0.0;
  int features = 0;  ///< coefficients per axis (incl. intercept)
  /// Mean over validation units (groups or blocks) of the unit's mean over axes of
  /// (held-out RMS / rated)²: every orientation a new use may bring counts once, however many
  /// rows it was recorded with.
  double score = 0.0;
  std::array<double, 6> rms_si{};  ///< held-out RMS per axis, N and N·m
  /// Each fold's share of `score` (its rows' mean squared error × its units / all units): they
  /// sum to score, and two candidates' shares, fold by fold, are the paired differences of the
  /// choice.
  std::vector<double> fold_score;
};

/// One comparison of the choice: how much lower the more complex candidate's score is than the
/// simpler one's (margin = Σ over folds of the paired differences) and the standard error of
/// that sum (√K × the sample standard deviation of the K per-fold differences).
struct ChoiceMargin {
  std::string simpler;  ///< "linear lambda=0"
  std::string complex;
  double simpler_score = 0.0;
  double margin = 0.0;  ///< simpler score − complex score (> 0: the complex one validated better)
  double se = 0.0;
  /// Taken when margin > se: better by more than one standard error of the comparison.
  [[nodiscard]] bool Significant() const { return margin > se; }
};

/// A candidate as the choice prints it: "linear lambda=0.03".
[[nodiscard]] std::string CandidateName(const CandidateScore& c);

/// The paired comparison of two candidates' per-fold scores (equal fold counts).
[[nodiscard]] ChoiceMargin CompareCandidates(const CandidateScore& simpler,
                                             const CandidateScore& complex);

/// Whether `a` is simpler than `b`: fewer coefficients, then a smaller ridge λ (each step away
/// from plain least squares is one more thing chosen on the data). Neither is simpler than the
/// other when both agree (two families of equal size): they are alternatives of one rank.
[[nodiscard]] bool SimplerThan(const CandidateScore& a, const CandidateScore& b);

/// The one-standard-error choice (docs/calibration.md): going through the ranks from the
/// simplest, the best-scoring candidate of a rank is taken unless some more complex candidate
/// beats it by more than one standard error of their paired per-fold differences. Returns its
/// index; *over_simplest (chosen against the best candidate of the simplest rank, when they
/// differ) and *challenger (the more complex candidate closest to being taken, in margin / SE;
/// empty `complex` when there is none) say why.
[[nodiscard]] std::size_t ChooseOneStandardError(const std::vector<CandidateScore>& candidates,
                                                 ChoiceMargin* over_simplest,
                                                 ChoiceMargin* challenger);

/// Held-out error of one block (or validation group) under the chosen model.
struct BlockScore {
  int block = 0;  ///< block or group index
  std::size_t rows = 0;
  double t_start_s = 0.0;
  double t_end_s = 0.0;
  double rms_pct = 0.0;                 ///< RMS over axes of error in % of rated
  std::array<double, 6> mean_wrench{};  ///< mean reference load of the block
};

struct FitResult {
  fw::FloatCalibration cal{};
  ModelKind kind = ModelKind::kLinear;
  double lambda = 0.0;
  int folds = 0;
  std::string validation;        ///< what was held out: "12 groups (load direction within 5°)"
  bool lambda_at_bound = false;  ///< λ is the largest tried: the penalty is not resolved
  std::size_t rows = 0;
  int block_count = 0;
  std::string block_method;
  std::array<double, 6> rated{};
  std::array<double, 6> heldout_rms_si{};      ///< held-out RMS per axis (whole blocks), N, N·m
  std::array<double, 6> heldout_p95_si{};      ///< 95th percentile of held-out |error|
  std::array<double, 6> residual_sigma_si{};   ///< training residual σ (dof-corrected)
  std::array<double, 6> fit_uncertainty_si{};  ///< parameter part: σ·sqrt(p_eff / n)
  double load_condition = 0.0;    ///< condition number of [1, wrench/rated] over the rows
  double design_condition = 0.0;  ///< condition number of the chosen model's standardised design
  std::vector<CandidateScore> candidates;
  ChoiceMargin over_simplest;  ///< the chosen against the simplest (empty when it is the simplest)
  ChoiceMargin challenger;     ///< the strongest more complex candidate not taken (may be empty)
  Eigen::MatrixXd heldout_residual;  ///< rows × 6: prediction − reference, held-out
  std::vector<BlockScore> blocks;    ///< worst first
  std::vector<BlockScore> groups;    ///< held-out error per validation group, worst first
  /// Blocks whose held-out error is an outlier (over 3.5 robust σ above the median block):
  /// reported, and down-weighted in the robust variant.
  std::vector<int> suspect_blocks;
  /// The robust variant beat the plain fit by more than one standard error and was used.
  bool robust = false;
  ChoiceMargin robust_margin;  ///< plain (simpler) against down-weighted (when a block is suspect)
  double plain_score = 0.0;    ///< cross-validated score without / with the down-weighting
  double robust_score = 0.0;   ///< (0 when no block is suspect)
};

/// Fits and cross-validates. Throws std::invalid_argument when the data cannot support a fit
/// (fewer than 2 blocks, fewer rows than coefficients, NaN).
[[nodiscard]] FitResult FitCalibration(const RigData& data, const FitOptions& options);

/// sqrt(λmax/λmin) of a symmetric Gram matrix (infinity when it is singular).
[[nodiscard]] double GramCondition(const Eigen::MatrixXd& gram);

/// Condition number (σmax/σmin) of [1, wrench ./ rated] — how well a load set excites all axes.
[[nodiscard]] double LoadSetCondition(const Eigen::MatrixXd& wrench,
                                      const std::array<double, 6>& rated);
/// The same for a list of loads (N, N·m) and a rated range.
[[nodiscard]] double LoadSetCondition(const std::vector<Wrench>& loads, const Wrench& rated);

}  // namespace ftstack::cal
