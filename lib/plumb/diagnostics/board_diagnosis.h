// plumb/diagnostics/board_diagnosis.h — diagnose the board's IMUs (SPEC 6, "Several IMUs of one
// board"; what `plumb diagnose` does with several IMUs): each IMU alone, and the IMUs across.
//
// Per IMU: IMU k diagnosed alone (Diagnose) on its own samples over IMU 0's still segments as it
// samples them (estimation::SegmentOnBoardImu), with the board's model (without the
// gyroscope's terms when it has none): its own fit and the candidates its own misfit points to.
// An IMU whose fit alone has chi^2/dof above its band (estimation::Chi2AboveBand, the one
// meaning of "consistent with the noise"),
//
//   chi2_k / dof_k > 1 + 3 sqrt(2 / dof_k),
//
// has a misfit of its own: whatever the other IMUs do, its own error model misses something,
// and its candidates say what.
//
// Across: the board's fit (estimation::CalibrateBoard: the attitudes shared, each IMU its rotation
// into the body) is the IMUs' fits alone with one constraint more: every IMU sees each pose's one
// attitude through one fixed rotation. The models are nested and the residuals the same, so
// when the IMUs move as one rigid board (and the noise models hold),
//
//   D = chi2_board - sum_k chi2_k  ~  chi^2(dof_board - sum_k dof_k)                  (LR test)
//
// The test takes the IMUs within their noise alone (an IMU's own misfit would enter the shared
// attitudes and be read as the board's), refitting them together when some are left out.
// A D / (its dof) above the same band says the IMUs do not keep one rotation between them
// across the session (an IMU on its own damping that sags between poses, one loose in its
// socket), or that one IMU's stamps are not the others' clock: a misfit no single IMU has.
//
// Example:
//   BoardDiagnosis d = DiagnoseBoard(session.series, session.other_imus, segments, model, site,
//                                    options);
//   for (const ImuDiagnosis& imu : d.imus) if (imu.own_misfit) ...;
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "plumb/core/session.h"
#include "plumb/diagnostics/diagnose.h"

namespace plumb::diagnostics {

/// One IMU of the board diagnosed alone.
struct ImuDiagnosis {
  int instance = 0;       ///< its number on the board (IMU 0: 0)
  std::string name;       ///< where it was read from ("IMU2", "SCALED_IMU3"; IMU 0: empty)
  Diagnosis diagnosis;    ///< its fit alone and its candidates
  /// The upper edge of its fit's chi^2 band (estimation::Chi2BandUpper times dof; 0 without
  /// dof), and whether its chi^2 is above it: a misfit of its own.
  double chi2_limit = 0;
  bool own_misfit = false;
};

/// Whether the IMUs move as one rigid board: the board's fit against the IMUs' fits alone,
/// over the IMUs whose fits alone are within their noise and pass their gates (an IMU's own
/// misfit would enter the shared attitudes and be read as the board's).
struct RigidBoardTest {
  /// The IMUs tested (places in BoardDiagnosis::imus, IMU 0 first); empty when `untested`.
  std::vector<std::size_t> imus;
  double chi2_board = 0;  ///< chi^2 of their fit together (attitudes shared)
  int dof_board = 0;
  double chi2_alone = 0;  ///< sum over them of their fits' chi^2 alone
  int dof_alone = 0;
  /// D = chi2_board - chi2_alone, on dof_board - dof_alone constraints; `limit` the upper edge
  /// of its band (Chi2BandUpper times the constraints).
  double difference() const { return chi2_board - chi2_alone; }
  int constraints() const { return dof_board - dof_alone; }
  double limit = 0;
  /// Why nothing was tested (empty: tested): IMU 0's own misfit, no other IMU within its
  /// noise, no constraint the data can test, residuals alone the board's fit lacks.
  std::string untested;
  bool holds() const { return untested.empty() && difference() <= limit; }
};

struct BoardDiagnosis {
  estimation::CalibrationResult board;  ///< the board's fit: every IMU, the attitudes shared
  /// The fit together of the IMUs RigidBoardTest tested, when they are not all of them.
  std::optional<estimation::CalibrationResult> rigid_board;
  std::vector<ImuDiagnosis> imus;       ///< IMU 0, then the board's others in their order
  RigidBoardTest rigid;
  /// Every IMU's model (IMU 0 first), as diagnosed.
  std::vector<model::Model> models;
  /// The board's next fit: every IMU whose own misfit has an advised effect (Recommended, an
  /// effect of the catalogue) takes it, refitted together; advised only when its chi^2/dof is
  /// below the board's (`board`): a recommendation never makes the user's own fit worse.
  struct Next {
    std::vector<model::Model> models;     ///< IMU 0's, then each other's
    estimation::CalibrationResult board;  ///< the board refitted with them
    bool advised = false;
  };
  std::optional<Next> next;
};

/// The models of BoardDiagnosis::Next, or nullopt when no IMU's own misfit has an advised
/// effect: `models` (IMU 0's first) with each such IMU's advice.
std::optional<std::vector<model::Model>> NextBoardModels(const std::vector<ImuDiagnosis>& imus,
                                                         const std::vector<model::Model>& models);

/// Whether `imu`'s fit alone is within its noise and passes its gates: one the rigid-board test
/// takes.
bool FitsAlone(const ImuDiagnosis& imu);

/// The rigid-board test over the IMUs of `imus` that fit alone (FitsAlone), `together` their
/// fit together: all of `imus` when none is left out.
RigidBoardTest TestRigidBoard(const std::vector<ImuDiagnosis>& imus,
                              const estimation::FitReport& together);

/// Diagnoses IMU 0 (`series0`, `model`) and the board's others (`board`, each with its model of
/// `board_models`, or `model` when it is empty: estimation::CalibrateBoard's) alone, fits them
/// together, tests the board's rigidity, and refits the board with each IMU's advice.
/// `segments` are IMU 0's. Throws what Diagnose and estimation::CalibrateBoard throw.
BoardDiagnosis DiagnoseBoard(const ImuSeries& series0, const std::vector<BoardImu>& board,
                             const std::vector<StillSegment>& segments, const model::Model& model,
                             const geo::Site& site, const DiagnoseOptions& options = {},
                             const std::vector<model::Model>& board_models = {});

}  // namespace plumb::diagnostics
