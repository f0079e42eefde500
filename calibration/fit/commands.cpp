#include "calibration/fit/commands.hpp"

#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "calibration/file/payload_file.hpp"
#include "calibration/file/slots.hpp"
#include "calibration/fit/apply.hpp"
#include "calibration/fit/excitation.hpp"
#include "calibration/fit/fit_report.hpp"
#include "calibration/fit/input_units.hpp"
#include "calibration/fit/known_mass.hpp"
#include "calibration/fit/payload.hpp"

namespace ftstack::cal {
namespace {

std::string Printf(const char* fmt, double a, double b, double c, double d, double e, double f) {
  char buf[512];
  std::snprintf(buf, sizeof buf, fmt, a, b, c, d, e, f);
  return buf;
}

/// A rig recording: with a reference wrench, or with known masses (mass_kg, arm_*_m, g*_mps2)
/// turned into one, plus the jig's load when asked to identify it (reported in *text).
Recording ReadRigRecording(const std::string& path, bool identify_jig, std::string* text) {
  ReadOptions opt;
  opt.require_bridges = true;
  Recording rec = ReadRecording(path, opt);
  if (!IsKnownMassRecording(rec)) {
    if (identify_jig) throw std::invalid_argument("--identify-jig needs a mass_kg column");
    for (const std::string& c : WrenchColumns()) (void)rec.Column(c);  // names the file
    return rec;
  }
  rec = WithReferenceFromMasses(rec);
  if (identify_jig) {
    const JigEstimate jig = IdentifyJig(rec);
    *text +=
        Printf("jig: %.4f ± %.4f kg, centre of mass %.2f %.2f %.2f mm", jig.mass_kg,
               jig.mass_sigma_kg, jig.com_m[0] * 1e3, jig.com_m[1] * 1e3, jig.com_m[2] * 1e3, 0) +
        Printf(" (± %.2f, %.2f, %.2f mm)\n", jig.com_sigma_m[0] * 1e3, jig.com_sigma_m[1] * 1e3,
               jig.com_sigma_m[2] * 1e3, 0, 0, 0);
    rec = WithJig(rec, jig);
  }
  return rec;
}

}  // namespace

FitOutcome FitFromRecording(const FitRequest& req) {
  FitOutcome out;
  std::string jig_text;
  Recording rec = ReadRigRecording(req.in_path, req.identify_jig, &jig_text);
  if (!req.rated) {
    throw std::invalid_argument(
        "fit needs the rated range: give --sensor FILE|builtin or --rated FX,FY,FZ,MX,MY,MZ");
  }
  FitOptions fo;
  fo.folds = req.folds;
  fo.by_group = req.by_group;
  fo.rated = *req.rated;
  const hal::AdcInfo assumed =
      req.adc ? *req.adc : DefaultAdc(static_cast<std::uint8_t>(rec.BridgeCount()));
  // Declared units: the fit is made for the declared converter, else for the assumed one; values
  // outside its range are refused (file:line:column), the b* columns converted in place.
  const FitInput input = PrepareFitInput(&rec, req.units, assumed);
  if (req.model_name != "auto") {
    const auto k = ParseModelKind(req.model_name);
    if (!k) throw std::invalid_argument("unknown --model '" + req.model_name + "'");
    fo.models = {*k};
  }
  BlockOptions bo;
  bo.scale = fo.rated;
  out.data = RigDataFromRecording(rec, bo);
  // Every axis must be excited (range against rated, independent of the others), or be
  // written flagged invalid when the user asks: never a row the data could not determine.
  const ExcitationOptions eo;
  const ExcitationReport ex = CheckExcitation(out.data.wrench, fo.rated, eo);
  if (ex.unexcited != 0 && !req.allow_unexcited) {
    throw std::invalid_argument(req.in_path + ": " + ex.Refusal(fo.rated, eo) +
                                ": refused (--allow-unexcited writes it flagged invalid)");
  }
  out.result = FitCalibration(out.data, fo);
  // Said once the recording is accepted (a refusal stays one line).
  out.text = jig_text + input.description + "\n";
  if (!req.adc && !input.declared.has_converter) {
    out.text += "converter: generic 24-bit, +-3.90625 mV/V (no --sensor)\n";
  }
  out.file = CalFileFromFit(out.result, input.adc, req.serial, req.date);
  RecordInputUnit(input, &out.file);
  out.file.cal.invalid_axes = ex.unexcited;
  (void)ToFixed(out.file, out.file.adc, &out.fixed);
  out.text += FitSummary(out.result, out.fixed);
  if (ex.unexcited != 0) {
    out.text += "warning: " + ex.Refusal(fo.rated, eo) +
                ": flagged invalid — ftd serves no value for " + AxisList(ex.unexcited) +
                " (NaN / 0, status bit 10)\n";
  }
  return out;
}

ApplyOutcome ApplyToFile(const std::string& cal_path, const std::string& in_path,
                         const std::string& out_path, const UnitOverrides& units) {
  ApplyOutcome res;
  const CalFile cal = LoadCalFile(cal_path);
  if (cal.cal.invalid_axes != 0) {
    res.log += "warning: " + cal_path + " flags axis " + AxisList(cal.cal.invalid_axes) +
               " invalid (not calibrated): its column holds 0, not a measurement\n";
  }
  ReadOptions opt;
  opt.require_bridges = true;
  Recording in = ReadRecording(in_path, opt);
  res.log += PrepareApplyInput(&in, units, cal, cal_path) + "\n";
  const Recording out = ApplyCalibration(cal, in);
  WriteRecording(out_path, out);
  res.log += "wrote " + std::to_string(in.rows()) + " rows to " + out_path + "\n";
  res.status = out.Column("status");
  return res;
}

std::string PayloadToFile(const std::string& in_path, const std::string& out_path,
                          double max_condition, const std::string& date) {
  PayloadFitOptions po;
  po.max_condition = max_condition;
  PayloadFit fit = FitPayload(PayloadReadingsFromRecording(ReadRecording(in_path)), po);
  fit.file.date = date;
  SavePayloadFile(out_path, fit.file);
  return PayloadSummary(fit) + "wrote " + out_path + "\n";
}

std::string ActiveSlotLine(const std::string& slots_dir, std::string* warning) {
  CalSlots slots(slots_dir);
  char slot = 0;
  const CalFile f = slots.LoadActive(&slot, warning);
  return std::string("slot ") + slot + ": serial " + f.serial + ", date " + f.date + ", source " +
         f.source + "\n";
}

std::string WorstCaseLine(const fw::LoadReport& rep) {
  const auto& e = rep.worst_case_error_si;
  return Printf(
      "worst-case fixed-point error: Fx %.3g N, Fy %.3g N, Fz %.3g N, Mx %.3g N·m, My %.3g N·m, "
      "Mz %.3g N·m\n",
      e[0], e[1], e[2], e[3], e[4], e[5]);
}

std::string VerifyCalFile(const std::string& path, bool* incomplete) {
  const CalFile cal = LoadCalFile(path);
  fw::LoadReport rep{};
  (void)ToFixed(cal, cal.adc, &rep);
  std::ostringstream o;
  *incomplete = cal.cal.invalid_axes != 0;
  if (*incomplete) {
    // Intact, but not a calibration of every axis: never "OK" alone.
    o << path << ": INCOMPLETE: axis " << AxisList(cal.cal.invalid_axes)
      << " flagged invalid (not excited on the rig): ftd serves no value for it (NaN / 0, "
         "status bit 10); the file itself is intact (CRC valid)\n";
  } else {
    o << path << ": OK (schema " << kCalSchema << ", " << int{cal.cal.channel_count}
      << " channels, " << int{cal.cal.product_count} << " second-order terms, temperature "
      << (cal.cal.temperature_compensated ? "compensated" : "not compensated") << ", serial "
      << cal.serial << ", CRC valid, fixed-point form matches)\n";
  }
  return o.str() + WorstCaseLine(rep);
}

std::string AtiImportSummary(const std::string& ati_path, const AtiImport& imp) {
  std::ostringstream o;
  o << ati_path << ": ATI calibration version " << imp.version << ", serial " << imp.file.serial
    << ", " << int{imp.file.cal.channel_count} << " gauges, matrix from "
    << (imp.used_user_axis ? "UserAxis rows" : "Axis rows / scale + BasicTransform") << "\n";
  for (std::size_t a = 0; a < 6; ++a) {
    o << "  " << kAxisNames[a] << " (" << (a < 3 ? "N" : "N*m") << "/V):";
    char buf[32];
    for (std::size_t c = 0; c < imp.file.cal.channel_count; ++c) {
      std::snprintf(buf, sizeof buf, " %10.5f", imp.file.cal.matrix[a][c]);
      o << buf;
    }
    o << "   rated " << imp.file.rated[a] << "\n";
  }
  fw::LoadReport rep{};
  (void)ToFixed(imp.file, imp.file.adc, &rep);
  return o.str() + WorstCaseLine(rep);
}

CheckResult RunCheck(const CheckRequest& req, std::string* text) {
  const CalFile cal = LoadCalFile(req.cal_path);
  CheckTool tool;
  if (!req.payload_path.empty()) {
    if (req.mass_kg || req.com_m) {
      throw std::invalid_argument("check: give either --payload or --mass-kg/--com-m, not both");
    }
    const PayloadFile p = LoadPayloadFile(req.payload_path);
    tool.mass_kg = p.mass_kg;
    tool.com_m = {p.com_m[0], p.com_m[1], p.com_m[2]};
  } else if (req.mass_kg) {
    tool.mass_kg = *req.mass_kg;
    if (req.com_m) tool.com_m = {(*req.com_m)[0], (*req.com_m)[1], (*req.com_m)[2]};
  } else {
    throw std::invalid_argument("check needs the tool: --payload FILE or --mass-kg M [--com-m]");
  }
  tool.mass_sigma_kg = req.mass_sigma_kg;
  tool.com_sigma_m = req.com_sigma_m;
  tool.pose_angle_sigma_rad = req.pose_angle_sigma_rad;
  ReadOptions opt;
  opt.require_bridges = true;
  Recording rec = ReadRecording(req.in_path, opt);
  const std::string used = PrepareApplyInput(&rec, req.units, cal, req.cal_path);
  const CheckResult r = CheckCalibration(CheckPosesFromRecording(cal, rec), tool, cal.uncertainty);
  *text = used + "\n" + CheckSummary(r, tool);
  return r;
}

}  // namespace ftstack::cal
