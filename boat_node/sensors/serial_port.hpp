#pragma once
/// \file
/// Opening a serial device for the sensor protocols: raw 8N1, no flow control, non-blocking.

#include <string>

namespace telltale::sensors {

/// Opens `device` at `baud` (4800 ... 921600) in raw 8N1 mode, non-blocking, close-on-exec, and
/// returns the file descriptor (the caller closes it). Throws std::invalid_argument for an
/// unsupported baud rate, std::system_error when the device cannot be opened or is not a tty.
[[nodiscard]] int open_serial_raw(const std::string& device, int baud);

}  // namespace telltale::sensors
