#include "report/fit_text.hpp"

#include <sstream>

namespace uphill {

std::string FitReportText(const FitReport& r) {
  std::ostringstream out;
  out << "method: " << MethodName(r.method) << ", n = " << r.n << ", dof = " << r.dof << "\n";
  for (const auto& p : r.parameters) {
    out << "  " << p.name << " = " << p.value << "  ± " << p.se_unscaled << " (unscaled)";
    if (p.se_scaled) out << "  ± " << *p.se_scaled << " (scaled by sqrt(chi2/dof))";
    out << "\n";
  }
  out << "  chi2 = " << r.chi2;
  if (r.reduced_chi2) out << ", chi2/dof = " << *r.reduced_chi2;
  if (r.p_value) out << ", p = " << *r.p_value;
  out << "\n";
  for (size_t i : r.outliers) out << "  outlier: row " << i + 1 << " of the data\n";
  for (const auto& d : r.downweighted) out << "  down-weighted: row " << d.row + 1 << " (weight " << d.weight << ")\n";
  for (const auto& n : r.notes) out << "  note: " << n << "\n";
  return out.str();
}

}  // namespace uphill
