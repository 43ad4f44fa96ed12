// kiln/log.hpp — one log for the host and every module; lines go to stderr. Errors a
// user must see in the window travel as values (Runtime::activeErrors), not via the log.
#pragma once

#include <sstream>
#include <string>
#include <utility>

namespace kiln {

// Concatenates anything streamable: str("pass ", id, " took ", ms, " ms").
// (g++ 12 has no <format>.)
template <class... A>
std::string str(A&&... a) {
    std::ostringstream os;
    (os << ... << std::forward<A>(a));
    return os.str();
}

namespace log {

enum class Level { Debug, Info, Warn, Error };

void write(Level, std::string message);
void setMinLevel(Level);

template <class... A> void debug(A&&... a) { write(Level::Debug, str(std::forward<A>(a)...)); }
template <class... A> void info(A&&... a) { write(Level::Info, str(std::forward<A>(a)...)); }
template <class... A> void warn(A&&... a) { write(Level::Warn, str(std::forward<A>(a)...)); }
template <class... A> void error(A&&... a) { write(Level::Error, str(std::forward<A>(a)...)); }

}  // namespace log
}  // namespace kiln
