// nfq_delay: holds every packet an iptables NFQUEUE rule hands it for a fixed time, then lets it
// go. The namespace tests' stand-in for `tc qdisc ... netem delay`: this machine's kernel has no
// sch_netem, but it has NFQUEUE. Run it inside the namespace whose packets it delays
// (`ip netns exec NS nfq_delay --queue N --delay-ms 200`) with a rule such as
// `iptables -A OUTPUT -o eth0 -j NFQUEUE --queue-num N`.
//
// Packets leave in arrival order, each `delay` after it arrived (a pure delay line: no jitter, no
// reordering, no loss while the queue stays under --max-held). Stops on SIGINT/SIGTERM, letting
// every held packet go first (counted as flushed, outside the hold statistics), and prints how
// many packets it held and for how long.
#include <arpa/inet.h>
#include <libnetfilter_queue/libnetfilter_queue.h>
#include <linux/netfilter.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <string>

namespace {

using Clock = std::chrono::steady_clock;

volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

struct Held {
  std::uint32_t id;
  Clock::time_point arrived;
};

struct State {
  std::deque<Held> held;
  std::chrono::milliseconds delay{200};
  std::size_t max_held = 10000;
  unsigned long long packets = 0;
  unsigned long long overflow = 0;
  unsigned long long flushed = 0;
  double hold_sum_ms = 0.0;
  double hold_max_ms = 0.0;
  double hold_min_ms = 1e9;
};

int on_packet(nfq_q_handle* queue, nfgenmsg*, nfq_data* data, void* user) {
  auto& st = *static_cast<State*>(user);
  const nfqnl_msg_packet_hdr* hdr = nfq_get_msg_packet_hdr(data);
  if (!hdr) return 0;
  const std::uint32_t id = ntohl(hdr->packet_id);
  if (st.held.size() >= st.max_held) {  // never grow without bound: pass it on at once
    ++st.overflow;
    return nfq_set_verdict(queue, id, NF_ACCEPT, 0, nullptr);
  }
  st.held.push_back({id, Clock::now()});
  return 0;
}

void release(nfq_q_handle* queue, State& st, bool all) {
  const auto now = Clock::now();
  while (!st.held.empty() && (all || now - st.held.front().arrived >= st.delay)) {
    const double held_ms =
        std::chrono::duration<double, std::milli>(now - st.held.front().arrived).count();
    nfq_set_verdict(queue, st.held.front().id, NF_ACCEPT, 0, nullptr);
    st.held.pop_front();
    if (all && held_ms < static_cast<double>(st.delay.count())) {
      ++st.flushed;  // let go early at shutdown: not a measure of the delay line
      continue;
    }
    ++st.packets;
    st.hold_sum_ms += held_ms;
    st.hold_max_ms = std::max(st.hold_max_ms, held_ms);
    st.hold_min_ms = std::min(st.hold_min_ms, held_ms);
  }
}

int usage() {
  std::fprintf(stderr, "usage: nfq_delay --queue N --delay-ms MS [--max-held PACKETS]\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  State st;
  int queue_num = -1;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    const long value = std::strtol(argv[i + 1], nullptr, 10);
    if (flag == "--queue") {
      queue_num = static_cast<int>(value);
    } else if (flag == "--delay-ms") {
      st.delay = std::chrono::milliseconds(value);
    } else if (flag == "--max-held") {
      st.max_held = static_cast<std::size_t>(value);
    } else {
      return usage();
    }
  }
  if (argc % 2 == 0 || queue_num < 0 || queue_num > 65535 || st.delay.count() < 0) return usage();

  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: poll() returns EINTR and the loop ends
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  nfq_handle* handle = nfq_open();
  if (!handle) {
    std::fprintf(stderr, "nfq_delay: nfq_open failed (needs CAP_NET_ADMIN): %s\n",
                 std::strerror(errno));
    return 1;
  }
  nfq_q_handle* queue =
      nfq_create_queue(handle, static_cast<std::uint16_t>(queue_num), &on_packet, &st);
  if (!queue) {
    std::fprintf(stderr, "nfq_delay: cannot bind queue %d: %s\n", queue_num, std::strerror(errno));
    nfq_close(handle);
    return 1;
  }
  nfq_set_mode(queue, NFQNL_COPY_META, 0);  // the verdict needs only the packet id
  nfq_set_queue_maxlen(queue, static_cast<std::uint32_t>(st.max_held + 1024));
  const int fd = nfq_fd(handle);
  std::printf("nfq_delay ready: queue=%d delay_ms=%lld\n", queue_num,
              static_cast<long long>(st.delay.count()));
  std::fflush(stdout);

  char buf[65536];
  while (!g_stop) {
    int timeout_ms = 100;
    if (!st.held.empty()) {
      const auto due = st.held.front().arrived + st.delay;
      timeout_ms = static_cast<int>(std::clamp<long long>(
          std::chrono::duration_cast<std::chrono::milliseconds>(due - Clock::now()).count() + 1, 0,
          100));
    }
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN)) {
      const ssize_t n = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
      if (n > 0) nfq_handle_packet(handle, buf, static_cast<int>(n));
      // ENOBUFS: the kernel dropped queue messages (counted by the kernel); keep going.
    }
    release(queue, st, false);
  }
  release(queue, st, true);
  nfq_destroy_queue(queue);
  nfq_close(handle);
  std::printf(
      "nfq_delay stopped: packets=%llu overflow=%llu flushed=%llu hold_ms_min=%.1f mean=%.1f "
      "max=%.1f\n",
      st.packets, st.overflow, st.flushed, st.packets ? st.hold_min_ms : 0.0,
      st.packets ? st.hold_sum_ms / static_cast<double>(st.packets) : 0.0, st.hold_max_ms);
  return 0;
}
