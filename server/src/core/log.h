// Structured logs: one line per event, "ts=... level=... msg=... key=value ...", on stderr.
// Levels are set once at start-up by the server's --log-level flag.
#pragma once

#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

namespace graspsim {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

void SetLogLevel(LogLevel level);
bool LogEnabled(LogLevel level);
// Parses "debug", "info", "warn", "error"; returns false for anything else.
bool ParseLogLevel(std::string_view text, LogLevel* level);

using LogField = std::pair<std::string_view, std::string>;
void Log(LogLevel level, std::string_view message, std::initializer_list<LogField> fields = {});

}  // namespace graspsim
