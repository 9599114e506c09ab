/* sc_socketcan.c: SocketCAN CAN_RAW node behind a syscall adapter, see sc_socketcan.h. */
#include "sc_socketcan.h"

#include <errno.h>
#include <string.h>
#include <time.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/errqueue.h>
#include <linux/net_tstamp.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include "sc_err.h"

_Static_assert(sizeof(sc_socketcan_raw) == sizeof(struct canfd_frame), "canfd_frame layout");
_Static_assert(offsetof(sc_socketcan_raw, data) == offsetof(struct canfd_frame, data),
               "canfd_frame layout");

/* ---- pure conversions ----------------------------------------------------------------------- */

uint32_t sc_socketcan_errf_from_linux(uint32_t can_id, const uint8_t data[8])
{
    uint32_t e = 0;
    if (can_id & CAN_ERR_BUSOFF) {
        e |= SC_CAN_ERRF_BUS_OFF;
    }
    if (can_id & CAN_ERR_CRTL) {
        const uint8_t c = data[1];
        if (c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) {
            e |= SC_CAN_ERRF_PASSIVE;
        }
        if (c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) {
            e |= SC_CAN_ERRF_WARNING;
        }
        if ((c & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) || c == 0u) {
            e |= SC_CAN_ERRF_CTRL;
        }
    }
    if (can_id & CAN_ERR_TX_TIMEOUT) {
        e |= SC_CAN_ERRF_CTRL;
    }
    if (can_id & (CAN_ERR_PROT | CAN_ERR_BUSERROR | CAN_ERR_ACK | CAN_ERR_TRX | CAN_ERR_LOSTARB)) {
        e |= SC_CAN_ERRF_PROTOCOL;
    }
    if (can_id & CAN_ERR_RESTARTED) {
        e |= SC_CAN_ERRF_RESTARTED;
    }
    return e;
}

int sc_socketcan_from_raw(const sc_socketcan_raw *r, int is_fd, sc_can_frame *out)
{
    *out = (sc_can_frame){0};
    if (r->can_id & CAN_ERR_FLAG) {
        out->flags = SC_CAN_FLAG_ERR;
        out->id = sc_socketcan_errf_from_linux(r->can_id, r->data);
        out->len = CAN_ERR_DLC;
        memcpy(out->data, r->data, CAN_ERR_DLC);
        return 0;
    }
    if (is_fd) {
        if (!sc_can_len_valid(r->len, SC_CAN_FLAG_FD)) {
            return SC_ERR_RANGE;
        }
        out->flags = (uint8_t)(SC_CAN_FLAG_FD | ((r->flags & CANFD_BRS) ? SC_CAN_FLAG_BRS : 0u));
    } else {
        if (r->len > CAN_MAX_DLEN) {
            return SC_ERR_RANGE;
        }
        if (r->can_id & CAN_RTR_FLAG) {
            out->flags |= SC_CAN_FLAG_RTR;
        }
    }
    if (r->can_id & CAN_EFF_FLAG) {
        out->flags |= SC_CAN_FLAG_EXT;
        out->id = r->can_id & CAN_EFF_MASK;
    } else {
        out->id = r->can_id & CAN_SFF_MASK;
    }
    out->len = r->len;
    if (!(out->flags & SC_CAN_FLAG_RTR)) {
        memcpy(out->data, r->data, r->len);
    }
    return 0;
}

int sc_socketcan_to_raw(const sc_can_frame *f, sc_socketcan_raw *out, int *is_fd)
{
    *out = (sc_socketcan_raw){0};
    *is_fd = 0;
    if (f->flags & SC_CAN_FLAG_ERR) {
        uint32_t id = CAN_ERR_FLAG;
        if (f->id & SC_CAN_ERRF_BUS_OFF) {
            id |= CAN_ERR_BUSOFF;
        }
        if (f->id & SC_CAN_ERRF_PASSIVE) {
            id |= CAN_ERR_CRTL;
            out->data[1] |= CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE;
        }
        if (f->id & SC_CAN_ERRF_WARNING) {
            id |= CAN_ERR_CRTL;
            out->data[1] |= CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING;
        }
        if (f->id & SC_CAN_ERRF_CTRL) {
            id |= CAN_ERR_CRTL;
            out->data[1] |= CAN_ERR_CRTL_RX_OVERFLOW;
        }
        if (f->id & SC_CAN_ERRF_PROTOCOL) {
            id |= CAN_ERR_PROT;
        }
        if (f->id & SC_CAN_ERRF_RESTARTED) {
            id |= CAN_ERR_RESTARTED;
        }
        out->can_id = id;
        out->len = CAN_ERR_DLC;
        return 0;
    }
    if (!sc_can_len_valid(f->len, f->flags)) {
        return SC_ERR_INVALID_ARG;
    }
    if (f->flags & SC_CAN_FLAG_EXT) {
        if (f->id > CAN_EFF_MASK) {
            return SC_ERR_INVALID_ARG;
        }
        out->can_id = f->id | CAN_EFF_FLAG;
    } else {
        if (f->id > CAN_SFF_MASK) {
            return SC_ERR_INVALID_ARG;
        }
        out->can_id = f->id;
    }
    if (f->flags & SC_CAN_FLAG_FD) {
        if (f->flags & SC_CAN_FLAG_RTR) {
            return SC_ERR_INVALID_ARG; /* no remote frames in CAN FD */
        }
        *is_fd = 1;
        out->flags = (f->flags & SC_CAN_FLAG_BRS) ? CANFD_BRS : 0u;
    } else if (f->flags & SC_CAN_FLAG_RTR) {
        out->can_id |= CAN_RTR_FLAG;
    }
    out->len = f->len;
    memcpy(out->data, f->data, f->len);
    return 0;
}

sc_socketcan_rawfilter sc_socketcan_filter_to_raw(const sc_can_filter *f)
{
    sc_socketcan_rawfilter r;
    if (f->flags & SC_CAN_FLAG_EXT) {
        r.can_id = (f->id & CAN_EFF_MASK) | CAN_EFF_FLAG;
        r.can_mask = (f->mask & CAN_EFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG;
    } else {
        r.can_id = f->id & CAN_SFF_MASK;
        r.can_mask = (f->mask & CAN_SFF_MASK) | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    return r;
}

/* ---- time stamp conversion ------------------------------------------------------------------ */

static int reading_usable(const sc_socketcan_clocks *r)
{
    return r->mono_after_ns >= r->mono_before_ns && r->real_ns != 0u;
}

int sc_socketcan_tsconv_estimate(sc_socketcan_tsconv *c, const sc_socketcan_clocks *r, size_t n)
{
    const sc_socketcan_clocks *best = NULL;
    for (size_t i = 0; i < n; i++) {
        if (reading_usable(&r[i]) &&
            (best == NULL || r[i].mono_after_ns - r[i].mono_before_ns <
                                 best->mono_after_ns - best->mono_before_ns)) {
            best = &r[i];
        }
    }
    if (best == NULL) {
        return SC_ERR_INVALID_ARG;
    }
    const uint64_t width = best->mono_after_ns - best->mono_before_ns;
    const uint64_t mid = best->mono_before_ns + width / 2u;
    c->offset_ns = (int64_t)mid - (int64_t)best->real_ns;
    c->uncertainty_ns = (width + 1u) / 2u;
    c->valid = 1;
    return 0;
}

int sc_socketcan_tsconv_stepped(const sc_socketcan_tsconv *c, const sc_socketcan_clocks *r)
{
    if (!c->valid || !reading_usable(r)) {
        return 0;
    }
    /* the reading says the offset lies in [lo, hi]; the estimate, in offset +- uncertainty.
     * 1 ns of slack per side for the clocks' rounding to whole ns */
    const int64_t lo = (int64_t)r->mono_before_ns - (int64_t)r->real_ns;
    const int64_t hi = (int64_t)r->mono_after_ns - (int64_t)r->real_ns;
    const int64_t u = (int64_t)c->uncertainty_ns + 1;
    return hi < c->offset_ns - u || lo > c->offset_ns + u;
}

uint64_t sc_socketcan_tsconv_to_mono(const sc_socketcan_tsconv *c, uint64_t real_ns)
{
    if (!c->valid || real_ns == 0u) {
        return 0u;
    }
    const int64_t mono = (int64_t)real_ns + c->offset_ns;
    return mono > 0 ? (uint64_t)mono : 0u;
}

/* ---- the node ------------------------------------------------------------------------------- */

/* A fresh offset from SC_SOCKETCAN_CLOCK_READINGS readings. */
static int estimate_offset(sc_socketcan *s)
{
    sc_socketcan_clocks r[SC_SOCKETCAN_CLOCK_READINGS];
    for (size_t i = 0; i < SC_SOCKETCAN_CLOCK_READINGS; i++) {
        const int rc = s->sys->read_clocks(s->sys_user, &r[i]);
        if (rc != 0) {
            return rc;
        }
    }
    return sc_socketcan_tsconv_estimate(&s->tsconv, r, SC_SOCKETCAN_CLOCK_READINGS);
}

/* The kernel's REALTIME stamp on the HAL clock, re-estimating the offset first when a reading
 * shows that REALTIME was stepped. When the clocks cannot be read the held offset serves. */
static uint64_t stamp_to_mono(sc_socketcan *s, uint64_t real_ns)
{
    if (real_ns == 0u) {
        return 0u;
    }
    sc_socketcan_clocks now;
    if (s->sys->read_clocks(s->sys_user, &now) == 0 &&
        (!s->tsconv.valid || sc_socketcan_tsconv_stepped(&s->tsconv, &now))) {
        const int was_valid = s->tsconv.valid;
        if (estimate_offset(s) == 0 && was_valid) {
            s->tsconv.steps++;
        }
    }
    return sc_socketcan_tsconv_to_mono(&s->tsconv, real_ns);
}

static void update_state(sc_socketcan *s, const sc_socketcan_raw *r, uint32_t errf)
{
    if (errf & SC_CAN_ERRF_BUS_OFF) {
        s->state = SC_CAN_STATE_BUS_OFF;
    } else if (errf & SC_CAN_ERRF_RESTARTED) {
        s->state = SC_CAN_STATE_ERROR_ACTIVE;
    } else if (errf & SC_CAN_ERRF_PASSIVE) {
        s->state = SC_CAN_STATE_ERROR_PASSIVE;
    } else if ((errf & SC_CAN_ERRF_WARNING) && s->state != SC_CAN_STATE_ERROR_PASSIVE) {
        s->state = SC_CAN_STATE_ERROR_WARNING;
    } else if ((r->can_id & CAN_ERR_CRTL) && (r->data[1] & CAN_ERR_CRTL_ACTIVE)) {
        s->state = SC_CAN_STATE_ERROR_ACTIVE;
    }
    if (r->can_id & CAN_ERR_CNT) {
        s->counters.tx_err = r->data[6];
        s->counters.rx_err = r->data[7];
    }
}

static int node_recv(void *ctx, sc_can_frame *out)
{
    sc_socketcan *s = ctx;
    /* bounded: frames the HAL cannot represent are skipped, at most 8 per call */
    for (int attempt = 0; attempt < 8; attempt++) {
        sc_socketcan_raw r;
        int is_fd = 0;
        uint64_t ts = 0;
        uint32_t drops = s->kernel_drops;
        const int rc = s->sys->recv(s->sys_user, s->handle, &r, &is_fd, &ts, &drops);
        if (rc < 0) {
            return rc;
        }
        if (rc == 0) {
            return SC_ERR_WOULD_BLOCK;
        }
        if (drops != s->kernel_drops) {
            s->counters.rx_dropped += drops - s->kernel_drops;
            s->kernel_drops = drops;
        }
        if (sc_socketcan_from_raw(&r, is_fd, out) != 0) {
            s->rx_unconvertible++;
            continue;
        }
        out->ts_ns = stamp_to_mono(s, ts);
        if (out->flags & SC_CAN_FLAG_ERR) {
            update_state(s, &r, out->id);
            s->rx_error_frames++;
        } else {
            s->rx_frames++;
        }
        return 0;
    }
    return SC_ERR_WOULD_BLOCK;
}

static int node_send(void *ctx, const sc_can_frame *f)
{
    sc_socketcan *s = ctx;
    if (f->flags & SC_CAN_FLAG_ERR) {
        return SC_ERR_INVALID_ARG;
    }
    sc_socketcan_raw r;
    int is_fd;
    int rc = sc_socketcan_to_raw(f, &r, &is_fd);
    if (rc != 0) {
        return rc;
    }
    if (is_fd && !s->fd_capable) {
        return SC_ERR_NOT_SUPPORTED;
    }
    if (s->state == SC_CAN_STATE_BUS_OFF) {
        s->counters.tx_dropped++;
        return SC_ERR_CAN_BUS_OFF;
    }
    rc = s->sys->send(s->sys_user, s->handle, &r, is_fd);
    if (rc != 0) {
        s->counters.tx_dropped++;
        return rc;
    }
    s->tx_frames++;
    return 0;
}

static int node_set_filters(void *ctx, const sc_can_filter *filters, size_t count)
{
    sc_socketcan *s = ctx;
    if (count > SC_CAN_MAX_FILTERS) {
        return SC_ERR_NO_SPACE;
    }
    sc_socketcan_rawfilter raw[SC_CAN_MAX_FILTERS];
    if (count == 0u) {
        raw[0] = (sc_socketcan_rawfilter){0u, 0u}; /* accept everything */
        return s->sys->set_filters(s->sys_user, s->handle, raw, 1u);
    }
    for (size_t i = 0; i < count; i++) {
        raw[i] = sc_socketcan_filter_to_raw(&filters[i]);
    }
    return s->sys->set_filters(s->sys_user, s->handle, raw, count);
}

static int node_get_state(void *ctx, sc_can_state *state, sc_can_counters *counters)
{
    const sc_socketcan *s = ctx;
    if (state) {
        *state = s->state;
    }
    if (counters) {
        *counters = s->counters;
    }
    return 0;
}

static const sc_can_ops node_ops = {
    .send = node_send,
    .recv = node_recv,
    .set_filters = node_set_filters,
    .get_state = node_get_state,
};

int sc_socketcan_open(sc_socketcan *s, const sc_socketcan_sys *sys, void *sys_user,
                      const char *ifname)
{
    *s = (sc_socketcan){
        .sys = sys, .sys_user = sys_user, .handle = -1, .state = SC_CAN_STATE_STOPPED};
    if (ifname == NULL || ifname[0] == '\0' || strlen(ifname) >= IFNAMSIZ) {
        return SC_ERR_INVALID_ARG;
    }
    int fd_capable = 0;
    const int h = sys->open(sys_user, ifname, &fd_capable);
    if (h < 0) {
        return h;
    }
    s->handle = h;
    s->fd_capable = fd_capable;
    const int rc = estimate_offset(s);
    if (rc != 0) {
        sys->close(sys_user, h);
        s->handle = -1;
        return rc == SC_ERR_INVALID_ARG ? SC_ERR_IO : rc;
    }
    s->state = SC_CAN_STATE_ERROR_ACTIVE;
    return 0;
}

void sc_socketcan_close(sc_socketcan *s)
{
    if (s->handle >= 0) {
        s->sys->close(s->sys_user, s->handle);
        s->handle = -1;
    }
    s->state = SC_CAN_STATE_STOPPED;
}

sc_can_dev sc_socketcan_dev(sc_socketcan *s)
{
    return (sc_can_dev){.ops = &node_ops, .ctx = s};
}

/* ---- the POSIX adapter ---------------------------------------------------------------------- */

static int posix_open(void *u, const char *ifname, int *fd_capable)
{
    (void)u;
    const int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        return SC_ERR_IO;
    }
    struct ifreq ifr;
    memset(&ifr, 0, sizeof ifr);
    strncpy(ifr.ifr_name, ifname, IFNAMSIZ - 1);
    if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
        close(fd);
        return SC_ERR_IO;
    }
    const int ifindex = ifr.ifr_ifindex;
    *fd_capable = 0;
    if (ioctl(fd, SIOCGIFMTU, &ifr) == 0 && ifr.ifr_mtu == (int)CANFD_MTU) {
        const int on = 1;
        if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) == 0) {
            *fd_capable = 1;
        }
    }
    const can_err_mask_t em = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_BUSOFF |
                              CAN_ERR_BUSERROR | CAN_ERR_RESTARTED | CAN_ERR_CNT;
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &em, sizeof em) != 0) {
        close(fd);
        return SC_ERR_IO;
    }
    const int ts_flags = SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
    if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPING, &ts_flags, sizeof ts_flags) != 0) {
        const int on = 1;
        (void)setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
    }
    const int on = 1;
    (void)setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = ifindex;
    if (bind(fd, (struct sockaddr *)&addr, sizeof addr) != 0) {
        close(fd);
        return SC_ERR_IO;
    }
    return fd;
}

static int posix_set_filters(void *u, int h, const sc_socketcan_rawfilter *f, size_t n)
{
    (void)u;
    struct can_filter kf[SC_CAN_MAX_FILTERS];
    if (n > SC_CAN_MAX_FILTERS) {
        return SC_ERR_NO_SPACE;
    }
    for (size_t i = 0; i < n; i++) {
        kf[i].can_id = f[i].can_id;
        kf[i].can_mask = f[i].can_mask;
    }
    if (setsockopt(h, SOL_CAN_RAW, CAN_RAW_FILTER, kf, (socklen_t)(n * sizeof kf[0])) != 0) {
        return SC_ERR_IO;
    }
    return 0;
}

static uint64_t ts_to_ns(const struct timespec *t)
{
    return (uint64_t)t->tv_sec * 1000000000u + (uint64_t)t->tv_nsec;
}

static int posix_recv(void *u, int h, sc_socketcan_raw *out, int *is_fd, uint64_t *ts_ns,
                      uint32_t *drops)
{
    (void)u;
    struct canfd_frame fr;
    union {
        char buf[CMSG_SPACE(sizeof(struct timespec) * 3) + CMSG_SPACE(sizeof(uint32_t)) +
                 CMSG_SPACE(sizeof(struct timespec))];
        struct cmsghdr align;
    } ctrl;
    struct iovec iov = {.iov_base = &fr, .iov_len = sizeof fr};
    struct msghdr msg = {.msg_iov = &iov,
                         .msg_iovlen = 1,
                         .msg_control = ctrl.buf,
                         .msg_controllen = sizeof ctrl.buf};
    const ssize_t n = recvmsg(h, &msg, MSG_DONTWAIT);
    if (n < 0) {
        return (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) ? 0 : SC_ERR_IO;
    }
    if (n == (ssize_t)CANFD_MTU) {
        *is_fd = 1;
    } else if (n == (ssize_t)CAN_MTU) {
        *is_fd = 0;
    } else {
        return SC_ERR_IO; /* CAN XL or truncated: not ours */
    }
    memcpy(out, &fr, sizeof fr);
    if (!*is_fd) {
        memset(out->data + CAN_MAX_DLEN, 0, sizeof out->data - CAN_MAX_DLEN);
        out->flags = 0;
    }
    *ts_ns = 0;
    for (struct cmsghdr *c = CMSG_FIRSTHDR(&msg); c != NULL; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level != SOL_SOCKET) {
            continue;
        }
        if (c->cmsg_type == SO_TIMESTAMPING) {
            struct timespec t[3];
            memcpy(t, CMSG_DATA(c), sizeof t);
            *ts_ns = ts_to_ns(&t[0]);
        } else if (c->cmsg_type == SO_TIMESTAMPNS) {
            struct timespec t;
            memcpy(&t, CMSG_DATA(c), sizeof t);
            *ts_ns = ts_to_ns(&t);
        } else if (c->cmsg_type == SO_RXQ_OVFL) {
            memcpy(drops, CMSG_DATA(c), sizeof *drops);
        }
    }
    return 1; /* the stamp stays on CLOCK_REALTIME: the node converts it (sc_socketcan_tsconv) */
}

static int posix_read_clocks(void *u, sc_socketcan_clocks *out)
{
    (void)u;
    struct timespec m0, rt, m1;
    if (clock_gettime(CLOCK_MONOTONIC, &m0) != 0 || clock_gettime(CLOCK_REALTIME, &rt) != 0 ||
        clock_gettime(CLOCK_MONOTONIC, &m1) != 0) {
        return SC_ERR_IO;
    }
    *out = (sc_socketcan_clocks){
        .mono_before_ns = ts_to_ns(&m0), .real_ns = ts_to_ns(&rt), .mono_after_ns = ts_to_ns(&m1)};
    return 0;
}

static int posix_send(void *u, int h, const sc_socketcan_raw *f, int is_fd)
{
    (void)u;
    const size_t len = is_fd ? CANFD_MTU : CAN_MTU;
    const ssize_t n = write(h, f, len);
    if (n == (ssize_t)len) {
        return 0;
    }
    if (n < 0 && (errno == ENOBUFS || errno == EAGAIN || errno == EWOULDBLOCK)) {
        return SC_ERR_WOULD_BLOCK;
    }
    return SC_ERR_IO;
}

static void posix_close(void *u, int h)
{
    (void)u;
    close(h);
}

static const sc_socketcan_sys posix_sys = {
    .open = posix_open,
    .set_filters = posix_set_filters,
    .recv = posix_recv,
    .send = posix_send,
    .close = posix_close,
    .read_clocks = posix_read_clocks,
};

const sc_socketcan_sys *sc_socketcan_sys_posix(void)
{
    return &posix_sys;
}
