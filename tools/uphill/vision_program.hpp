// Two programs, one command line. OpenCV's video and image libraries bring ~250 shared libraries
// that the dynamic loader maps and relocates at every start (Debian builds them with immediate
// binding): 0.1 s of CPU and ~70 MB resident before a command runs. So `uphill` does not link
// them: the commands that need them - track, calibrate, analyse-track, fit and report of an
// experiment folder (its videos), serve, bench track and bench report - run in the sibling program `uphill-vision`, built from the same command definitions (flags, help, man
// pages and completion come from `uphill` alone) plus src/vision.
//
// In `uphill` such a command's definition parses and checks its flags as usual and then calls
// RunInVisionProgram, which replaces the process by `uphill-vision` (found next to the running
// program, in the build tree and when installed) with the same arguments; in `uphill-vision`
// (compiled with UPHILL_VISION_PROGRAM = 1) the same definition runs the work itself.
#pragma once

#ifndef UPHILL_VISION_PROGRAM
#define UPHILL_VISION_PROGRAM 0
#endif

namespace uphill::cli {

// The program's arguments, as main received them (argv[0] included).
void RememberArguments(int argc, char** argv);

// Replaces this process by `uphill-vision` with the remembered arguments. Throws InputError
// (exit 2) when the sibling is missing or cannot be run.
[[noreturn]] void RunInVisionProgram();

}  // namespace uphill::cli
