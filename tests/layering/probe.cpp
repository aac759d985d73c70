// Compiled by tests/layering/CMakeLists.txt, once per probe, with UPHILL_PROBE_HEADER naming one
// header and the include paths of one layer's library: it compiles exactly when that layer may
// include that header.
#include UPHILL_PROBE_HEADER
