// `uphill paper-figures -o DIR`: the seed paper's model figures redrawn from uphill's model and
// motion (SVG + PNG + the gnuplot script of each, and an index.html gallery). Where
// docs/physics.md ("The seed paper's errors") shows the paper's formula wrong (eq. 8 and its
// speed: the separatrix, not a release at s), the corrected physics is drawn and the paper's
// curve is added, labelled as such. The figures: src/app/paper_figures.hpp.
#include <filesystem>
#include <iostream>

#include "app/paper_figures.hpp"
#include "bench/support.hpp"
#include "commands.hpp"

namespace fs = std::filesystem;

namespace uphill::cli {

void AddPaperFiguresCommand(CLI::App& app) {
  auto dir = std::make_shared<std::string>("paper-figures");
  auto data = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("paper-figures", "Redraw the seed paper's figures (SVG, PNG, index.html)");
  cmd->add_option("-o,--out", *dir, "output folder")->capture_default_str();
  cmd->add_option("--data", *data, "folder with the sample experiments (default: the repository's data/)");
  cmd->callback([dir, data] {
    const std::string data_dir =
        data->empty() ? fs::path(bench::FindUpward("data/series1-fixed-D")).parent_path().string() : *data;
    for (const std::string& written : WritePaperFigures(*dir, data_dir)) std::cout << written << "\n";
  });
}

}  // namespace uphill::cli
