// GEOS's interrupt (geos_c.h: GEOS_interruptRegisterCallback, GEOS_interruptRequest) tied to a
// run's Progress, so that a long GEOS operation (the union of a large coast) stops when the run
// is cancelled instead of running to its end without a report.
#pragma once

#include <memory>

#include "globemesh/progress.hpp"

namespace globemesh::coast {

/// While alive, GEOS operations on this thread stop within about 0.1 s once `parent` asks to stop,
/// those that check for interrupts (overlay and union do; validity tests may not, and a loop
/// of short calls should call poll()). GEOS calls its interrupt callback (one for the process in
/// GEOS 3.11) as it works; ours
/// repeats the run's last report to `parent` at most every 50 ms, and when it returns false
/// requests GEOS's interrupt: the GEOS call in progress then fails (a null geometry, an error
/// code) and interrupted() or poll() tell the caller to throw Cancelled instead of an error. Pass
/// progress() on, not `parent`: it keeps the last report. An empty `parent` does nothing.
class GeosInterrupt {
public:
    explicit GeosInterrupt(Progress parent);
    ~GeosInterrupt();
    GeosInterrupt(const GeosInterrupt &) = delete;
    GeosInterrupt &operator=(const GeosInterrupt &) = delete;

    /// `parent` as seen by the run: records each report for the callback to repeat.
    const Progress &progress() const { return progress_; }
    /// True once the progress asked to stop while a GeosInterrupt was alive on this thread.
    static bool interrupted();
    /// Throws Cancelled when the run asked to stop (asking it again when 50 ms have passed): for
    /// loops of short GEOS calls, which GEOS itself may not check, and for a GEOS call that
    /// failed because it was interrupted. Does nothing without a GeosInterrupt on this thread.
    static void poll();

    struct State;

private:
    std::unique_ptr<State> state_;
    Progress progress_;
};

} // namespace globemesh::coast
