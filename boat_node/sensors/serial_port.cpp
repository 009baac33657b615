#include "serial_port.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>
#include <system_error>

namespace telltale::sensors {
namespace {

speed_t baud_constant(int baud) {
  switch (baud) {
    case 4800:
      return B4800;
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
  }
}

[[noreturn]] void fail(int fd, const std::string& what) {
  const int e = errno;
  ::close(fd);
  throw std::system_error(e, std::generic_category(), what);
}

}  // namespace

int open_serial_raw(const std::string& device, int baud) {
  const speed_t speed = baud_constant(baud);
  const int fd = ::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw std::system_error(errno, std::generic_category(), "open " + device);
  termios tio{};
  if (::tcgetattr(fd, &tio) != 0) fail(fd, device + " is not a tty");
  ::cfmakeraw(&tio);  // 8 data bits, no parity, no echo, no line editing, no CR/LF mapping
  tio.c_cflag |= CLOCAL | CREAD;
  tio.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB | PARENB);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0 ||
      ::tcsetattr(fd, TCSANOW, &tio) != 0)
    fail(fd, "configure " + device);
  return fd;
}

}  // namespace telltale::sensors
