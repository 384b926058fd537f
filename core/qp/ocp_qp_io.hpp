#pragma once
// OCP-QP dump files: one QP per line as a JSON object (JSON Lines), with every matrix, vector,
// bound and index list and the solver settings, so the identical problem can be given to other
// solvers. Format: docs/qp-dump-format.md. Not for the control loop (allocates, does I/O).
#include <iosfwd>
#include <string>

#include "core/qp/ocp_qp.hpp"
#include "core/qp/qp_riccati_ipm.hpp"

namespace mixpilot {

// Writes qp (and the settings) as one line of JSON, terminated by '\n'. Numbers are printed with
// 17 significant digits (exact round trip); absent bounds as ±1e30. With `start`, the warm
// start the solve began from goes with it (`warm`, and `start` unless warm is cold): a QP of a
// closed loop as the loop solved it.
void write_ocp_qp_json(std::ostream& out, const OcpQp& qp, const QpRiccatiIpmSettings& settings,
                       const std::string& name, const OcpQpSolution* start = nullptr,
                       QpWarmStart warm = QpWarmStart::cold);

// Parses one line written by write_ocp_qp_json. Returns false (and leaves qp unspecified) on a
// malformed line; error describes the problem. With `start` and `warm`, the record's warm start
// (sized to qp's dims, zero and cold when the record has none).
bool read_ocp_qp_json(const std::string& line, OcpQp& qp, QpRiccatiIpmSettings& settings,
                      std::string& name, std::string& error, OcpQpSolution* start = nullptr,
                      QpWarmStart* warm = nullptr);

}  // namespace mixpilot
