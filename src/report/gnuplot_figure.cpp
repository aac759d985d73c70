#include "report/gnuplot_figure.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/atomic_file.hpp"
#include "model/environment_error.hpp"
#include "model/input_error.hpp"

namespace uphill {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// gnuplot does not report a full disk: it exits 0 and leaves a truncated file. So an image is
// accepted only when it ends as its format ends: an SVG document with its closing tag, a PNG with
// its IEND chunk (PNG specification, section 11.2.5: length 0, "IEND", CRC AE 42 60 82).
bool CompleteSvg(const std::string& s) {
  const auto end = s.find_last_not_of(" \t\r\n");
  return end != std::string::npos && end >= 5 && s.compare(end - 5, 6, "</svg>") == 0;
}

// A PDF file ends with its end-of-file marker (ISO 32000-1, 7.5.5), then at most a line end.
bool CompletePdf(const std::string& s) {
  const auto end = s.find_last_not_of(" \t\r\n");
  return s.rfind("%PDF-", 0) == 0 && end != std::string::npos && end >= 4 && s.compare(end - 4, 5, "%%EOF") == 0;
}

bool CompletePng(const std::string& s) {
  static const std::string signature("\x89PNG\r\n\x1a\n", 8);
  static const std::string iend("\0\0\0\0IEND\xae\x42\x60\x82", 12);
  return s.size() >= signature.size() + iend.size() && s.compare(0, signature.size(), signature) == 0 &&
         s.compare(s.size() - iend.size(), iend.size(), iend) == 0;
}

// fsync of a finished file: a write error the kernel held back (a full disk with delayed
// allocation) shows here, before the file is renamed into place.
void SyncFile(const fs::path& path, const std::string& figure) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const int saved = errno;
    if (fd >= 0) ::close(fd);
    throw EnvironmentError("figure " + figure + ": " + path.filename().string() + " cannot be saved: " + std::strerror(saved));
  }
  ::close(fd);
}

// Runs `gnuplot -e ASSIGNMENTS SCRIPT` in `dir`, its output into `log`; spawned directly (no
// shell), so that several figures can be drawn at once from threads (figure_pool.hpp) and each
// call waits for its own child only. Throws EnvironmentError starting with `what` when gnuplot
// fails (with gnuplot's complaint, which names the script's line) or cannot be started; a missing
// gnuplot is the machine's problem, not the figure's, so that message names no figure and is the
// same for every figure (FigurePool reports it once).
void RunGnuplot(const fs::path& dir, const std::string& assignments, const std::string& script, const fs::path& log,
                const std::string& what) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::string program = "gnuplot", e = "-e", a = assignments, s = script;
  char* argv[] = {program.data(), e.data(), a.data(), s.data(), nullptr};
  pid_t pid = 0;
  const int spawned = ::posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned == ENOENT) throw EnvironmentError("gnuplot not found (install Debian's gnuplot-nox)");
  if (spawned != 0) throw EnvironmentError(what + ": gnuplot cannot be started: " + std::strerror(spawned));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw EnvironmentError(what + ": waiting for gnuplot: " + std::strerror(errno));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string complaint = Slurp(log);
    while (!complaint.empty() && (complaint.back() == '\n' || complaint.back() == ' ')) complaint.pop_back();
    if (complaint.empty())
      complaint = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                      : "exit status " + std::to_string(WEXITSTATUS(status));
    throw EnvironmentError(what + ": gnuplot failed: " + complaint);
  }
}

// A private folder for gnuplot's output, removed with everything in it however RenderFigure ends.
class RenderFolder {
 public:
  RenderFolder(const fs::path& dir, const std::string& name) {
    std::string pattern = (dir / ("." + name + ".render-XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw EnvironmentError((dir / (name + ".svg")).string() + ": cannot create a temporary folder: " +
                             std::strerror(errno));
    path_ = pattern;
  }
  ~RenderFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// The figure's four files are already what this call would write: the same numbers and script,
// and whole images made after them. gnuplot would draw the same images again, so a second report
// of an unchanged experiment reuses them. The images must be newer than the script and the data:
// a run stopped between writing those and renaming its images leaves older images, redrawn here.
bool UpToDate(const fs::path& dir, const std::string& name, const std::string& data, const std::string& script,
              bool pdf) {
  const fs::path dat = dir / (name + ".dat"), gp = dir / (name + ".gp");
  const fs::path svg = dir / (name + ".svg"), png = dir / (name + ".png"), pdf_file = dir / (name + ".pdf");
  std::error_code e;
  for (const fs::path& p : {dat, gp, svg, png})
    if (!fs::is_regular_file(fs::symlink_status(p, e))) return false;
  if (pdf && !fs::is_regular_file(fs::symlink_status(pdf_file, e))) return false;
  const auto inputs = std::max(fs::last_write_time(dat, e), fs::last_write_time(gp, e));
  if (e || fs::last_write_time(svg, e) < inputs || fs::last_write_time(png, e) < inputs || e) return false;
  if (pdf && (fs::last_write_time(pdf_file, e) < inputs || e || !CompletePdf(Slurp(pdf_file)))) return false;
  return Slurp(dat) == data && Slurp(gp) == script && CompleteSvg(Slurp(svg)) && CompletePng(Slurp(png));
}

}  // namespace

void RenderFigure(const GnuplotFigure& f, const std::string& directory) {
  // Absolute: the gnuplot command runs after a cd into it, and names its log by this path.
  const fs::path dir = fs::absolute(directory);
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) throw EnvironmentError(dir.string() + ": cannot open the folder: " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{dir_fd};
  // Anything but a regular file where an output goes is refused before anything is written.
  for (const std::string& file : FigureFiles(f.name, f.pdf)) {
    const fs::path target = dir / file;
    const fs::file_status st = fs::symlink_status(target);
    if (fs::exists(st) && !fs::is_regular_file(st))
      throw EnvironmentError(target.string() + ": is " + (fs::is_directory(st) ? "a folder" : "not a regular file") +
                             ": not replaced");
  }
  std::ostringstream script;
  script << "# " << f.name << ".gp: " << f.title << "\n"
         << "# Generated by uphill; edit and run `gnuplot " << f.name << ".gp` here to restyle.\n"
         << "# Lengths in mm.\n"
         << "if (!exists(\"svg_out\")) svg_out = '" << f.name << ".svg'\n"
         << "if (!exists(\"png_out\")) png_out = '" << f.name << ".png'\n"
         << (f.pdf ? "if (!exists(\"pdf_out\")) pdf_out = '" + f.name + ".pdf'\n" : "")
         << "set encoding utf8\n"
         << "set terminal svg size 900,600 dynamic enhanced font 'DejaVu Sans,15' background rgb 'white'\n"
         << "set output svg_out\n"
         << "set grid lc rgb '#dddddd'\n"
         // Below the plot: a key inside the axes covered points (the sample's Y − X figure).
         << "set key below height 1\n"
         << "set border lw 1.2\n"
         << f.plot << "\n"
         << "set terminal pngcairo size 1350,900 enhanced font 'DejaVu Sans,15' background rgb 'white'\n"
         << "set output png_out\n"
         << "replot\n";
  if (f.pdf)
    script << "set terminal pdfcairo size 15cm,10cm enhanced font 'DejaVu Sans,9' background rgb 'white'\n"
           << "set output pdf_out\n"
           << "replot\n";
  script << "unset output\n";
  if (UpToDate(dir, f.name, f.data, script.str(), f.pdf)) return;
  WriteFileAtomically((dir / (f.name + ".dat")).string(), f.data);
  WriteFileAtomically((dir / (f.name + ".gp")).string(), script.str());

  const RenderFolder render(dir, f.name);
  const std::string folder = render.path().filename().string();  // our own characters only
  const fs::path svg = render.path() / (f.name + ".svg"), png = render.path() / (f.name + ".png");
  const fs::path pdf = render.path() / (f.name + ".pdf");
  const fs::path log = render.path() / "gnuplot.log";
  const std::string script_file = (dir / (f.name + ".gp")).string();
  RunGnuplot(dir,
             "svg_out='" + folder + "/" + f.name + ".svg'; png_out='" + folder + "/" + f.name + ".png'" +
                 (f.pdf ? "; pdf_out='" + folder + "/" + f.name + ".pdf'" : ""),
             f.name + ".gp", log, "figure " + f.name + " (" + script_file + ")");
  if (!CompleteSvg(Slurp(svg)) || !CompletePng(Slurp(png)) || (f.pdf && !CompletePdf(Slurp(pdf))))
    throw EnvironmentError("figure " + f.name + " (" + script_file + "): gnuplot left an incomplete image (is the disk full?) in " +
                           dir.string() + "; the previous images, if any, are unchanged");
  SyncFile(svg, f.name);
  SyncFile(png, f.name);
  if (f.pdf) SyncFile(pdf, f.name);
  const int render_fd = ::open(render.path().c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (render_fd < 0) throw EnvironmentError(render.path().string() + ": cannot be opened: " + std::strerror(errno));
  try {
    RenameIntoPlaceAt(render_fd, f.name + ".svg", dir_fd, dir.string(), f.name + ".svg");
    RenameIntoPlaceAt(render_fd, f.name + ".png", dir_fd, dir.string(), f.name + ".png");
    if (f.pdf) RenameIntoPlaceAt(render_fd, f.name + ".pdf", dir_fd, dir.string(), f.name + ".pdf");
  } catch (...) {
    ::close(render_fd);
    throw;
  }
  ::close(render_fd);
}

std::vector<std::string> FigureFiles(const std::string& name, bool pdf) {
  std::vector<std::string> files = {name + ".dat", name + ".gp", name + ".svg", name + ".png"};
  if (pdf) files.push_back(name + ".pdf");
  return files;
}

}  // namespace uphill
