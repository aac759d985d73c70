// What every benchmark takes besides its own knobs.
#pragma once

#include <string>

namespace uphill::bench {

struct CommonOptions {
  std::string python = "/usr/bin/python3";  // the Python that runs the peers (tools/bench/*.py)
  std::string doc;                           // --doc: the file to record in (default docs/benchmarks.md)
  bool no_doc = false;                       // --no-doc: record nothing
  std::string command = "uphill bench";      // the command line as run, for the record
};

}  // namespace uphill::bench
