// Socket-level experiment behind vrflow's TCP write size (docs/transport.md, "16 MiB"): a
// ping-pong of SIZE bytes between two processes over 127.0.0.1 with the socket settings and the
// write pattern of vrflow's links, so their cost can be measured apart from vrflow.
//   cc -O2 -o tcp_write_chunks bench/transport/tcp_write_chunks.c
//   ./tcp_write_chunks MODE NONBLOCKING SIZE ROUNDS MAX_WRITE
// MODE 0: buffers left to autotuning (as raw-tcp), 1: SO_SNDBUF 4 MiB, 2: SO_SNDBUF and
// SO_RCVBUF 4 MiB (vrflow before 2026-11-27d). NONBLOCKING 1: non-blocking + poll, as the
// daemons' I/O threads. MAX_WRITE: bytes per write call (0: all at once). Prints the median
// one-way time (half a round trip) after the first tenth of the rounds.
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
static int mode, nb;
static size_t chunk;
static void tune(int f) {
  int one = 1, b = 4 << 20;
  setsockopt(f, IPPROTO_TCP, TCP_NODELAY, &one, 4);
  if (mode >= 1) setsockopt(f, SOL_SOCKET, SO_SNDBUF, &b, 4);
  if (mode == 2) setsockopt(f, SOL_SOCKET, SO_RCVBUF, &b, 4);
  if (nb) fcntl(f, F_SETFL, O_NONBLOCK);
}
static void io(int f, char* p, size_t n, int w) {
  while (n) {
    size_t k = w && chunk && n > chunk ? chunk : n;
    ssize_t r = w ? write(f, p, k) : read(f, p, k);
    if (r < 0) {
      struct pollfd q = {f, w ? POLLOUT : POLLIN, 0};
      poll(&q, 1, -1);
      continue;
    }
    if (r == 0) exit(3);
    p += r, n -= r;
  }
}
static double now() {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1e6 + t.tv_nsec / 1e3;
}
static int cmp(const void* a, const void* b) {
  double x = *(double*)a, y = *(double*)b;
  return x < y ? -1 : x > y;
}
int main(int c, char** v) {
  mode = atoi(v[1]), nb = atoi(v[2]);
  size_t n = strtoul(v[3], 0, 0);
  int rounds = atoi(v[4]);
  chunk = strtoul(v[5], 0, 0);
  int l = socket(AF_INET, SOCK_STREAM, 0);
  struct sockaddr_in a = {AF_INET};
  a.sin_addr.s_addr = htonl(0x7f000001);
  socklen_t al = sizeof a;
  bind(l, (void*)&a, al), listen(l, 1), getsockname(l, (void*)&a, &al);
  char* buf = malloc(n);
  memset(buf, 7, n);
  if (!fork()) {
    int f = socket(AF_INET, SOCK_STREAM, 0);
    connect(f, (void*)&a, al), tune(f);
    for (int i = 0; i < rounds; i++) io(f, buf, n, 0), io(f, buf, n, 1);
    return 0;
  }
  int f = accept(l, 0, 0);
  tune(f);
  char* in = malloc(n);
  memset(in, 1, n);
  double* s = malloc(rounds * sizeof *s);
  for (int i = 0; i < rounds; i++) {
    double t = now();
    io(f, buf, n, 1), io(f, in, n, 0);
    s[i] = (now() - t) / 2;
  }
  wait(0);
  qsort(s + rounds / 10, rounds - rounds / 10, sizeof *s, cmp);
  printf("mode %d nb %d chunk %zu size %zu median one-way us %.1f\n", mode, nb, chunk, n,
         s[rounds / 10 + (rounds - rounds / 10) / 2]);
}
