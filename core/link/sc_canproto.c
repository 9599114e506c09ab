/* sc_canproto.c: table-driven codec of the sonocomp CAN protocol, see sc_canproto.h. */
#include "sc_canproto.h"

#include <math.h>

#include "sc_err.h"

#define Q14 0.00006103515625f /* 1/16384: quaternion components, range [-2, 2) */

#define E2E_SIGS                                                                                   \
    {"E2E_CRC", 0, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},                                            \
    {                                                                                              \
        "E2E_Counter", 8, 4, 0, 1.0f, 0.0f, 0.0f, 15.0f, ""                                        \
    }

#define SIG_POS(n, sb)                                                                             \
    {                                                                                              \
        n, sb, 16, 1, 0.05f, 0.0f, -1638.4f, 1638.35f, "mm"                                        \
    }
#define SIG_Q(n, sb)                                                                               \
    {                                                                                              \
        n, sb, 16, 1, Q14, 0.0f, -2.0f, 1.99993896484375f, ""                                      \
    }
#define SIG_FORCE(sb)                                                                              \
    {                                                                                              \
        "ContactForce", sb, 16, 0, 0.01f, 0.0f, 0.0f, 655.34f, "N"                                 \
    }
#define SIG_TRACKING(sb)                                                                           \
    {                                                                                              \
        "TrackingState", sb, 2, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""                                      \
    }

static const sc_can_sig sigs_cmd_case[] = {
    E2E_SIGS,
    {"CaseId", 16, 8, 0, 1.0f, 0.0f, 0.0f, 254.0f, ""},
};
static const sc_can_sig sigs_cmd_method[] = {
    E2E_SIGS,
    {"Method", 16, 2, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
};
static const sc_can_sig sigs_cmd_imaging[] = {
    E2E_SIGS,
    {"Depth", 16, 16, 0, 0.1f, 0.0f, 10.0f, 250.0f, "mm"},
    {"Gain", 32, 8, 1, 0.5f, 0.0f, -40.0f, 40.0f, "dB"},
    {"DynRange", 40, 8, 0, 1.0f, 0.0f, 20.0f, 100.0f, "dB"},
    {"TgcSlope", 48, 8, 0, 0.1f, 0.0f, 0.0f, 10.0f, "dB/cm"},
    {"ScanGeometry", 56, 2, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
};
static const sc_can_sig sigs_cmd_reset[] = {
    E2E_SIGS,
    {"ResetTarget", 16, 2, 0, 1.0f, 0.0f, 1.0f, 3.0f, ""},
};
static const sc_can_sig sigs_cmd_sync[] = {
    E2E_SIGS,
    {"FreshnessMid", 16, 24, 0, 1.0f, 0.0f, 0.0f, 16777215.0f, ""},
    {"FreshnessHigh", 40, 24, 0, 1.0f, 0.0f, 0.0f, 16777215.0f, ""},
};
static const sc_can_sig sigs_cmd_assess[] = {
    E2E_SIGS,
    {"AssessAction", 16, 2, 0, 1.0f, 0.0f, 1.0f, 2.0f, ""},
    {"AssessCall", 18, 2, 0, 1.0f, 0.0f, 0.0f, 2.0f, ""},
};
static const sc_can_sig sigs_cmd_vessels[] = {
    E2E_SIGS,
    {"HeartRate", 16, 8, 0, 1.0f, 0.0f, 30.0f, 200.0f, "bpm"},
    {"RespRate", 24, 8, 0, 1.0f, 0.0f, 0.0f, 40.0f, "1/min"},
    {"Valsalva", 32, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"Pulsation", 33, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
};
static const sc_can_sig sigs_cmd_doppler[] = {
    E2E_SIGS,
    {"ColourOn", 16, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"Prf", 24, 16, 0, 1.0f, 0.0f, 100.0f, 20000.0f, "Hz"},
    {"Steer", 40, 8, 1, 1.0f, 0.0f, -30.0f, 30.0f, "deg"},
    {"ColourGain", 48, 8, 1, 0.5f, 0.0f, -30.0f, 30.0f, "dB"},
};
static const sc_can_sig sigs_cmd_material[] = {
    E2E_SIGS,
    {"MaterialLabel", 16, 4, 0, 1.0f, 0.0f, 1.0f, 7.0f, ""},
    {"CgIterations", 20, 6, 0, 1.0f, 0.0f, 1.0f, 63.0f, ""},
    {"Corotated", 26, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"YoungsModulus", 32, 16, 0, 0.1f, 0.0f, 0.1f, 6553.4f, "kPa"},
    {"PoissonRatio", 48, 8, 0, 0.002f, 0.0f, 0.0f, 0.49f, ""},
    {"Damping", 56, 8, 0, 0.002f, 0.0f, 0.01f, 0.5f, "s"},
};
/* The cryptographic PDU (sc_secoc.h); the 40-bit MAC as two integer signals so that every
 * signal stays exact in float32 (MacA = MAC bytes 0..2, MacB = bytes 3..4, little-endian). */
static const sc_can_sig sigs_auth[] = {
    {"SenderId", 0, 4, 0, 1.0f, 0.0f, 0.0f, 15.0f, ""},
    {"Link", 4, 4, 0, 1.0f, 0.0f, 0.0f, 15.0f, ""},
    {"FreshnessLow", 8, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"MacA", 24, 24, 0, 1.0f, 0.0f, 0.0f, 16777215.0f, ""},
    {"MacB", 48, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
};
static const sc_can_sig sigs_pose_pos[] = {
    E2E_SIGS,
    SIG_POS("PosX", 16),
    SIG_POS("PosY", 32),
    SIG_POS("PosZ", 48),
};
static const sc_can_sig sigs_pose_quat[] = {
    E2E_SIGS,
    SIG_Q("QuatW", 16),
    SIG_Q("QuatX", 32),
    SIG_Q("QuatY", 48),
};
static const sc_can_sig sigs_pose_aux[] = {
    E2E_SIGS,
    SIG_Q("QuatZ", 16),
    SIG_FORCE(32),
    SIG_TRACKING(48),
};
static const sc_can_sig sigs_pose_fd[] = {
    E2E_SIGS,           SIG_POS("PosX", 16), SIG_POS("PosY", 32), SIG_POS("PosZ", 48),
    SIG_Q("QuatW", 64), SIG_Q("QuatX", 80),  SIG_Q("QuatY", 96),  SIG_Q("QuatZ", 112),
    SIG_FORCE(128),     SIG_TRACKING(144),
};
static const sc_can_sig sigs_status[] = {
    E2E_SIGS,
    {"EngineState", 16, 4, 0, 1.0f, 0.0f, 0.0f, 3.0f, ""},
    {"PhysMethod", 20, 2, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"ProbeContact", 22, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"ProbeLifted", 23, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"FaultBits", 24, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"DeadlineMisses", 40, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"ActiveCase", 56, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
};
static const sc_can_sig sigs_timing[] = {
    E2E_SIGS,
    {"WorstFrameTime", 16, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, "us"},
    {"VeinAreaRatio", 32, 16, 0, 0.001f, 0.0f, 0.0f, 65.534f, ""},
    {"ArteryAreaRatio", 48, 16, 0, 0.001f, 0.0f, 0.0f, 65.534f, ""},
};
static const sc_can_sig sigs_diag[] = {
    E2E_SIGS,
    {"PosesAccepted", 16, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"RejectedE2E", 32, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"RejectedPlausibility", 48, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"LiftEvents", 56, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
};

static const sc_can_sig sigs_auth_diag[] = {
    E2E_SIGS,
    {"CmdsAuthenticated", 16, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"AuthRejected", 32, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
    {"AuthBadMac", 48, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"AuthStale", 56, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
};

#define SIG_RATIO(n, sb)                                                                           \
    {                                                                                              \
        n, sb, 16, 0, 0.001f, 0.0f, 0.0f, 65.534f, ""                                              \
    }
#define SIG_AFORCE(n, sb)                                                                          \
    {                                                                                              \
        n, sb, 16, 0, 0.01f, 0.0f, 0.0f, 655.34f, "N"                                              \
    }
static const sc_can_sig sigs_assess_vessels[] = {
    E2E_SIGS,
    SIG_RATIO("VeinMinRatio", 16),
    SIG_RATIO("ArteryMinRatio", 32),
    SIG_RATIO("ThrombusMinRatio", 48),
};
static const sc_can_sig sigs_assess_force[] = {
    E2E_SIGS,
    SIG_AFORCE("VeinForce", 16),
    SIG_AFORCE("ArteryForce", 32),
    SIG_AFORCE("ThrombusForce", 48),
};
static const sc_can_sig sigs_assess_score[] = {
    E2E_SIGS,
    SIG_AFORCE("PeakForce", 16),
    {"VeinCoapted", 32, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"ArteryCoapted", 33, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"ThrombusCoapted", 34, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"ArteryOverCompressed", 35, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"TraineeCall", 36, 2, 0, 1.0f, 0.0f, 0.0f, 2.0f, ""},
    {"CaseFinding", 38, 2, 0, 1.0f, 0.0f, 0.0f, 2.0f, ""},
    {"CriteriaMet", 40, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"Score", 48, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"ScoreMax", 56, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"ArteryPunctured", 12, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"VeinPunctured", 13, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
};
static const sc_can_sig sigs_needle_pos[] = {
    E2E_SIGS,
    SIG_POS("TipX", 16),
    SIG_POS("TipY", 32),
    SIG_POS("TipZ", 48),
};
static const sc_can_sig sigs_needle_dir[] = {
    E2E_SIGS,
    SIG_Q("DirX", 16),
    SIG_Q("DirY", 32),
    SIG_Q("DirZ", 48),
};
static const sc_can_sig sigs_needle_aux[] = {
    E2E_SIGS,
    {"InsertDepth", 16, 16, 0, 0.05f, 0.0f, 0.0f, 3276.75f, "mm"},
    SIG_TRACKING(32),
};
static const sc_can_sig sigs_needle_status[] = {
    E2E_SIGS,
    {"TipVessel", 16, 4, 0, 1.0f, 0.0f, 0.0f, 15.0f, ""},
    {"NeedleTracked", 20, 1, 0, 1.0f, 0.0f, 0.0f, 1.0f, ""},
    {"LastPuncture", 24, 4, 0, 1.0f, 0.0f, 0.0f, 15.0f, ""},
    {"VeinPunctures", 32, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"ArteryPunctures", 40, 8, 0, 1.0f, 0.0f, 0.0f, 255.0f, ""},
    {"NeedleRejected", 48, 16, 0, 1.0f, 0.0f, 0.0f, 65535.0f, ""},
};

#define MSG(n, id, len, fd, cyc, to, sigs)                                                         \
    {                                                                                              \
        n, id, id, len, fd, cyc, to, 1u, (uint8_t)(sizeof(sigs) / sizeof((sigs)[0])), sigs         \
    }
#define MSG_AUTH(n, id)                                                                            \
    {                                                                                              \
        n, id, id, 8, 0, 0, 0, 0u, (uint8_t)(sizeof(sigs_auth) / sizeof(sigs_auth[0])), sigs_auth  \
    }

static const sc_can_msg_info msg_table[SC_MSG_COUNT] = {
    [SC_MSG_CMD_CASE] = MSG("CmdSelectCase", SC_CANID_CMD_CASE, 8, 0, 0, 0, sigs_cmd_case),
    [SC_MSG_CMD_METHOD] = MSG("CmdSetMethod", SC_CANID_CMD_METHOD, 8, 0, 0, 0, sigs_cmd_method),
    [SC_MSG_CMD_IMAGING] = MSG("CmdSetImaging", SC_CANID_CMD_IMAGING, 8, 0, 0, 0, sigs_cmd_imaging),
    [SC_MSG_CMD_RESET] = MSG("CmdReset", SC_CANID_CMD_RESET, 8, 0, 0, 0, sigs_cmd_reset),
    [SC_MSG_CMD_SYNC] = MSG("CmdFreshnessSync", SC_CANID_CMD_SYNC, 8, 0, 0, 0, sigs_cmd_sync),
    [SC_MSG_CMD_ASSESS] = MSG("CmdAssessment", SC_CANID_CMD_ASSESS, 8, 0, 0, 0, sigs_cmd_assess),
    [SC_MSG_CMD_VESSELS] = MSG("CmdVessels", SC_CANID_CMD_VESSELS, 8, 0, 0, 0, sigs_cmd_vessels),
    [SC_MSG_CMD_DOPPLER] = MSG("CmdDoppler", SC_CANID_CMD_DOPPLER, 8, 0, 0, 0, sigs_cmd_doppler),
    [SC_MSG_CMD_MATERIAL] =
        MSG("CmdMaterial", SC_CANID_CMD_MATERIAL, 8, 0, 0, 0, sigs_cmd_material),
    [SC_MSG_POSE_POS] = MSG("ProbePosePos", SC_CANID_POSE_POS, 8, 0, 10, 100, sigs_pose_pos),
    [SC_MSG_POSE_QUAT] = MSG("ProbePoseQuat", SC_CANID_POSE_QUAT, 8, 0, 10, 100, sigs_pose_quat),
    [SC_MSG_POSE_AUX] = MSG("ProbePoseAux", SC_CANID_POSE_AUX, 8, 0, 10, 100, sigs_pose_aux),
    [SC_MSG_POSE_FD] = MSG("ProbePoseFD", SC_CANID_POSE_FD, 20, 1, 10, 100, sigs_pose_fd),
    [SC_MSG_STATUS] = MSG("EngineStatus", SC_CANID_STATUS, 8, 0, 100, 0, sigs_status),
    [SC_MSG_TIMING] = MSG("EngineTiming", SC_CANID_TIMING, 8, 0, 100, 0, sigs_timing),
    [SC_MSG_DIAG] = MSG("TrackerDiag", SC_CANID_DIAG, 8, 0, 100, 0, sigs_diag),
    [SC_MSG_AUTH_DIAG] = MSG("AuthDiag", SC_CANID_AUTH_DIAG, 8, 0, 100, 0, sigs_auth_diag),
    [SC_MSG_AUTH_CASE] = MSG_AUTH("CmdAuthSelectCase", SC_CANID_AUTH_CASE),
    [SC_MSG_AUTH_METHOD] = MSG_AUTH("CmdAuthSetMethod", SC_CANID_AUTH_CASE + 1),
    [SC_MSG_AUTH_IMAGING] = MSG_AUTH("CmdAuthSetImaging", SC_CANID_AUTH_CASE + 2),
    [SC_MSG_AUTH_RESET] = MSG_AUTH("CmdAuthReset", SC_CANID_AUTH_CASE + 3),
    [SC_MSG_AUTH_SYNC] = MSG_AUTH("CmdAuthFreshnessSync", SC_CANID_AUTH_SYNC),
    [SC_MSG_AUTH_ASSESS] = MSG_AUTH("CmdAuthAssessment", SC_CANID_AUTH_ASSESS),
    [SC_MSG_AUTH_VESSELS] = MSG_AUTH("CmdAuthVessels", SC_CANID_AUTH_VESSELS),
    [SC_MSG_AUTH_DOPPLER] = MSG_AUTH("CmdAuthDoppler", SC_CANID_AUTH_DOPPLER),
    [SC_MSG_AUTH_MATERIAL] = MSG_AUTH("CmdAuthMaterial", SC_CANID_AUTH_MATERIAL),
    [SC_MSG_ASSESS_VESSELS] =
        MSG("AssessVessels", SC_CANID_ASSESS_VESSELS, 8, 0, 100, 0, sigs_assess_vessels),
    [SC_MSG_ASSESS_FORCE] =
        MSG("AssessForce", SC_CANID_ASSESS_FORCE, 8, 0, 100, 0, sigs_assess_force),
    [SC_MSG_ASSESS_SCORE] =
        MSG("AssessScore", SC_CANID_ASSESS_SCORE, 8, 0, 100, 0, sigs_assess_score),
    [SC_MSG_NEEDLE_POS] = MSG("NeedlePosePos", SC_CANID_NEEDLE_POS, 8, 0, 10, 100, sigs_needle_pos),
    [SC_MSG_NEEDLE_DIR] = MSG("NeedlePoseDir", SC_CANID_NEEDLE_DIR, 8, 0, 10, 100, sigs_needle_dir),
    [SC_MSG_NEEDLE_AUX] = MSG("NeedleAux", SC_CANID_NEEDLE_AUX, 8, 0, 10, 100, sigs_needle_aux),
    [SC_MSG_NEEDLE_STATUS] =
        MSG("NeedleStatus", SC_CANID_NEEDLE_STATUS, 8, 0, 100, 0, sigs_needle_status),
};
_Static_assert(SC_CANID_AUTH_ASSESS == SC_CANID_CMD_ASSESS + SC_CANID_AUTH_OFFSET, "auth ids");
_Static_assert(SC_MSG_AUTH_ASSESS - SC_MSG_AUTH_CASE == SC_MSG_CMD_ASSESS - SC_MSG_CMD_CASE,
               "one cryptographic PDU per command (assessment)");
_Static_assert(SC_CANID_AUTH_VESSELS == SC_CANID_CMD_VESSELS + SC_CANID_AUTH_OFFSET &&
                   SC_CANID_AUTH_DOPPLER == SC_CANID_CMD_DOPPLER + SC_CANID_AUTH_OFFSET,
               "auth ids");
_Static_assert(SC_MSG_AUTH_VESSELS - SC_MSG_AUTH_CASE == SC_MSG_CMD_VESSELS - SC_MSG_CMD_CASE &&
                   SC_MSG_AUTH_DOPPLER - SC_MSG_AUTH_CASE == SC_MSG_CMD_DOPPLER - SC_MSG_CMD_CASE,
               "one cryptographic PDU per command (vessels, Doppler)");
_Static_assert(SC_CANID_AUTH_MATERIAL == SC_CANID_CMD_MATERIAL + SC_CANID_AUTH_OFFSET &&
                   SC_MSG_AUTH_MATERIAL - SC_MSG_AUTH_CASE ==
                       SC_MSG_CMD_MATERIAL - SC_MSG_CMD_CASE,
               "one cryptographic PDU per command (material)");
_Static_assert(SC_CANID_AUTH_SYNC == SC_CANID_CMD_SYNC + SC_CANID_AUTH_OFFSET, "auth ids");
_Static_assert(SC_MSG_AUTH_SYNC - SC_MSG_AUTH_CASE == SC_MSG_CMD_SYNC - SC_MSG_CMD_CASE,
               "one cryptographic PDU per command");

_Static_assert(sizeof(sigs_pose_fd) / sizeof(sigs_pose_fd[0]) <= SC_CANPROTO_MAX_SIGS,
               "raise SC_CANPROTO_MAX_SIGS");
_Static_assert(sizeof(sigs_assess_score) / sizeof(sigs_assess_score[0]) <= SC_CANPROTO_MAX_SIGS,
               "raise SC_CANPROTO_MAX_SIGS");

const sc_can_msg_info *sc_canproto_info(sc_msg m)
{
    if ((unsigned)m >= (unsigned)SC_MSG_COUNT) {
        return NULL;
    }
    return &msg_table[m];
}

int sc_canproto_classify(const sc_can_frame *f, sc_msg *out)
{
    if (f->flags & (SC_CAN_FLAG_EXT | SC_CAN_FLAG_RTR | SC_CAN_FLAG_ERR)) {
        return SC_ERR_CAN_ID;
    }
    for (unsigned i = 0; i < (unsigned)SC_MSG_COUNT; i++) {
        const sc_can_msg_info *m = &msg_table[i];
        if (m->can_id != f->id) {
            continue;
        }
        const int is_fd = (f->flags & SC_CAN_FLAG_FD) != 0;
        if (is_fd != (m->fd != 0u) || f->len != m->len) {
            return SC_ERR_CAN_DLC;
        }
        *out = (sc_msg)i;
        return 0;
    }
    return SC_ERR_CAN_ID;
}

int64_t sc_canproto_get_raw(const uint8_t *data, const sc_can_sig *s)
{
    uint64_t v = 0;
    for (unsigned i = 0; i < s->bits; i++) {
        const unsigned bit = (unsigned)s->start_bit + i;
        v |= (uint64_t)((data[bit / 8u] >> (bit % 8u)) & 1u) << i;
    }
    if (s->is_signed && s->bits < 64u && (v & ((uint64_t)1 << (s->bits - 1u)))) {
        v |= ~(((uint64_t)1 << s->bits) - 1u);
    }
    return (int64_t)v;
}

void sc_canproto_put_raw(uint8_t *data, const sc_can_sig *s, int64_t raw)
{
    const uint64_t v = (uint64_t)raw;
    for (unsigned i = 0; i < s->bits; i++) {
        const unsigned bit = (unsigned)s->start_bit + i;
        const uint8_t mask = (uint8_t)(1u << (bit % 8u));
        if ((v >> i) & 1u) {
            data[bit / 8u] = (uint8_t)(data[bit / 8u] | mask);
        } else {
            data[bit / 8u] = (uint8_t)(data[bit / 8u] & (uint8_t)~mask);
        }
    }
}

int sc_canproto_phys_to_raw(const sc_can_sig *s, float phys, int64_t *raw)
{
    if (!isfinite(phys)) {
        return SC_ERR_NOT_FINITE;
    }
    const float r = roundf((phys - s->offset) / s->factor);
    const float lo = s->is_signed ? -ldexpf(1.0f, s->bits - 1) : 0.0f;
    const float hi = s->is_signed ? ldexpf(1.0f, s->bits - 1) - 1.0f : ldexpf(1.0f, s->bits) - 1.0f;
    if (!(r >= lo && r <= hi)) {
        return SC_ERR_CAN_SIGNAL;
    }
    *raw = (int64_t)r;
    return 0;
}

float sc_canproto_raw_to_phys(const sc_can_sig *s, int64_t raw)
{
    return (float)raw * s->factor + s->offset;
}

int sc_canproto_decode_phys(const sc_can_frame *f, sc_msg *msg, float *phys, size_t cap)
{
    sc_msg m;
    int rc = sc_canproto_classify(f, &m);
    if (rc != 0) {
        return rc;
    }
    const sc_can_msg_info *info = &msg_table[m];
    if (cap < info->sig_count) {
        return SC_ERR_NO_SPACE;
    }
    for (unsigned i = 0; i < info->sig_count; i++) {
        phys[i] =
            sc_canproto_raw_to_phys(&info->sigs[i], sc_canproto_get_raw(f->data, &info->sigs[i]));
    }
    *msg = m;
    return 0;
}

/* ---- helpers ------------------------------------------------------------------------------ */

static void frame_begin(sc_can_frame *f, sc_msg m)
{
    const sc_can_msg_info *info = &msg_table[m];
    *f = (sc_can_frame){0};
    f->id = info->can_id;
    f->len = info->len;
    f->flags = info->fd ? (uint8_t)(SC_CAN_FLAG_FD | SC_CAN_FLAG_BRS) : 0u;
}

/* Signal `idx` of message m (indices count the two E2E signals). */
static const sc_can_sig *sig_of(sc_msg m, unsigned idx)
{
    return &msg_table[m].sigs[idx];
}

static int put_phys(sc_can_frame *f, sc_msg m, unsigned idx, float v)
{
    int64_t raw;
    int rc = sc_canproto_phys_to_raw(sig_of(m, idx), v, &raw);
    if (rc == 0) {
        sc_canproto_put_raw(f->data, sig_of(m, idx), raw);
    }
    return rc;
}

static void put_u(sc_can_frame *f, sc_msg m, unsigned idx, uint32_t v)
{
    sc_canproto_put_raw(f->data, sig_of(m, idx), (int64_t)v);
}

static uint32_t sat_u(uint32_t v, uint32_t max)
{
    return v > max ? max : v;
}

static float get_phys(const sc_can_frame *f, sc_msg m, unsigned idx)
{
    return sc_canproto_raw_to_phys(sig_of(m, idx), sc_canproto_get_raw(f->data, sig_of(m, idx)));
}

static uint32_t get_u(const sc_can_frame *f, sc_msg m, unsigned idx)
{
    return (uint32_t)sc_canproto_get_raw(f->data, sig_of(m, idx));
}

static int in_range(const sc_can_frame *f, sc_msg m, unsigned idx)
{
    const sc_can_sig *s = sig_of(m, idx);
    const float v = get_phys(f, m, idx);
    /* half a step of slack: the DBC range is written in rounded decimals */
    const float slack = 0.5f * s->factor;
    return v >= s->min - slack && v <= s->max + slack;
}

static int protect(sc_can_frame *f, sc_msg m, uint8_t counter)
{
    return sc_e2e_protect_with(msg_table[m].data_id, counter, f->data, f->len);
}

/* ---- pose ---------------------------------------------------------------------------------- */

static int put_force_tracking(sc_can_frame *f, sc_msg m, unsigned idx, const sc_pose_msg *p)
{
    int rc = 0;
    if (p->force_valid) {
        if (p->force_n > sig_of(m, idx)->max) {
            return SC_ERR_CAN_SIGNAL; /* 0xFFFF is reserved for "not available" */
        }
        rc = put_phys(f, m, idx, p->force_n);
    } else {
        put_u(f, m, idx, SC_FORCE_NOT_AVAILABLE_RAW);
    }
    if (p->tracking > SC_TRACKING_LOST) {
        return SC_ERR_CAN_SIGNAL;
    }
    put_u(f, m, idx + 1u, p->tracking);
    return rc;
}

int sc_canproto_encode_pose(const sc_pose_msg *p, uint8_t counter, int fd, sc_can_frame *out,
                            size_t cap, size_t *n)
{
    int rc = 0;
    if (fd) {
        if (cap < 1u) {
            return SC_ERR_NO_SPACE;
        }
        sc_can_frame *f = &out[0];
        frame_begin(f, SC_MSG_POSE_FD);
        for (unsigned i = 0; i < 3u && rc == 0; i++) {
            rc = put_phys(f, SC_MSG_POSE_FD, 2u + i, p->pos_mm[i]);
        }
        for (unsigned i = 0; i < 4u && rc == 0; i++) {
            rc = put_phys(f, SC_MSG_POSE_FD, 5u + i, p->q[i]);
        }
        if (rc == 0) {
            rc = put_force_tracking(f, SC_MSG_POSE_FD, 9u, p);
        }
        if (rc == 0) {
            rc = protect(f, SC_MSG_POSE_FD, counter);
        }
        *n = rc == 0 ? 1u : 0u;
        return rc;
    }
    if (cap < 3u) {
        return SC_ERR_NO_SPACE;
    }
    frame_begin(&out[0], SC_MSG_POSE_POS);
    frame_begin(&out[1], SC_MSG_POSE_QUAT);
    frame_begin(&out[2], SC_MSG_POSE_AUX);
    for (unsigned i = 0; i < 3u && rc == 0; i++) {
        rc = put_phys(&out[0], SC_MSG_POSE_POS, 2u + i, p->pos_mm[i]);
    }
    for (unsigned i = 0; i < 3u && rc == 0; i++) {
        rc = put_phys(&out[1], SC_MSG_POSE_QUAT, 2u + i, p->q[i]);
    }
    if (rc == 0) {
        rc = put_phys(&out[2], SC_MSG_POSE_AUX, 2u, p->q[3]);
    }
    if (rc == 0) {
        rc = put_force_tracking(&out[2], SC_MSG_POSE_AUX, 3u, p);
    }
    for (unsigned i = 0; i < 3u && rc == 0; i++) {
        rc = protect(&out[i], (sc_msg)((unsigned)SC_MSG_POSE_POS + i), counter);
    }
    *n = rc == 0 ? 3u : 0u;
    return rc;
}

static void get_force_tracking(const sc_can_frame *f, sc_msg m, unsigned idx, sc_pose_msg *p)
{
    const uint32_t raw = get_u(f, m, idx);
    p->force_valid = raw != SC_FORCE_NOT_AVAILABLE_RAW;
    p->force_n = p->force_valid ? get_phys(f, m, idx) : 0.0f;
    p->tracking = (uint8_t)get_u(f, m, idx + 1u);
}

int sc_canproto_decode_pose_part(const sc_can_frame *f, sc_pose_msg *p)
{
    sc_msg m;
    int rc = sc_canproto_classify(f, &m);
    if (rc != 0) {
        return rc;
    }
    switch (m) {
    case SC_MSG_POSE_POS:
        for (unsigned i = 0; i < 3u; i++) {
            p->pos_mm[i] = get_phys(f, m, 2u + i);
        }
        return 1;
    case SC_MSG_POSE_QUAT:
        for (unsigned i = 0; i < 3u; i++) {
            p->q[i] = get_phys(f, m, 2u + i);
        }
        return 2;
    case SC_MSG_POSE_AUX:
        p->q[3] = get_phys(f, m, 2u);
        get_force_tracking(f, m, 3u, p);
        return 4;
    case SC_MSG_POSE_FD:
        for (unsigned i = 0; i < 3u; i++) {
            p->pos_mm[i] = get_phys(f, m, 2u + i);
        }
        for (unsigned i = 0; i < 4u; i++) {
            p->q[i] = get_phys(f, m, 5u + i);
        }
        get_force_tracking(f, m, 9u, p);
        return (int)SC_POSE_PARTS_ALL;
    case SC_MSG_CMD_CASE:
    case SC_MSG_CMD_METHOD:
    case SC_MSG_CMD_IMAGING:
    case SC_MSG_CMD_RESET:
    case SC_MSG_CMD_SYNC:
    case SC_MSG_CMD_ASSESS:
    case SC_MSG_CMD_VESSELS:
    case SC_MSG_CMD_DOPPLER:
    case SC_MSG_CMD_MATERIAL:
    case SC_MSG_STATUS:
    case SC_MSG_TIMING:
    case SC_MSG_DIAG:
    case SC_MSG_AUTH_DIAG:
    case SC_MSG_AUTH_CASE:
    case SC_MSG_AUTH_METHOD:
    case SC_MSG_AUTH_IMAGING:
    case SC_MSG_AUTH_RESET:
    case SC_MSG_AUTH_SYNC:
    case SC_MSG_AUTH_ASSESS:
    case SC_MSG_AUTH_VESSELS:
    case SC_MSG_AUTH_DOPPLER:
    case SC_MSG_AUTH_MATERIAL:
    case SC_MSG_ASSESS_VESSELS:
    case SC_MSG_ASSESS_FORCE:
    case SC_MSG_ASSESS_SCORE:
    case SC_MSG_NEEDLE_POS:
    case SC_MSG_NEEDLE_DIR:
    case SC_MSG_NEEDLE_AUX:
    case SC_MSG_NEEDLE_STATUS:
    case SC_MSG_COUNT:
        break;
    }
    return SC_ERR_CAN_ID;
}

/* ---- commands ------------------------------------------------------------------------------ */

sc_msg sc_canproto_cmd_msg(sc_cmd_kind k)
{
    switch (k) {
    case SC_CMD_SELECT_CASE:
        return SC_MSG_CMD_CASE;
    case SC_CMD_SET_METHOD:
        return SC_MSG_CMD_METHOD;
    case SC_CMD_SET_IMAGING:
        return SC_MSG_CMD_IMAGING;
    case SC_CMD_RESET:
        return SC_MSG_CMD_RESET;
    case SC_CMD_SYNC_FRESHNESS:
        return SC_MSG_CMD_SYNC;
    case SC_CMD_ASSESS:
        return SC_MSG_CMD_ASSESS;
    case SC_CMD_VESSELS:
        return SC_MSG_CMD_VESSELS;
    case SC_CMD_DOPPLER:
        return SC_MSG_CMD_DOPPLER;
    case SC_CMD_MATERIAL:
        return SC_MSG_CMD_MATERIAL;
    }
    return SC_MSG_COUNT;
}

/* CmdAssessment: a reset carries no call, a call carries normal or DVT. */
static int assess_pair_ok(uint32_t action, uint32_t call)
{
    return (action == SC_ASSESS_ACTION_RESET && call == SC_ASSESS_CALL_NONE) ||
           (action == SC_ASSESS_ACTION_CALL &&
            (call == SC_ASSESS_CALL_NORMAL || call == SC_ASSESS_CALL_DVT));
}

/* CmdMaterial's fields: integers checked against their ranges, values put and range-checked
 * as the decoder will (signals 2..7). */
static int encode_material(sc_can_frame *f, sc_msg m, const sc_material_cmd *c)
{
    int rc = c->label >= SC_MATERIAL_LABEL_MIN && c->label <= SC_MATERIAL_LABEL_MAX &&
                     c->cg_iterations >= 1u && c->cg_iterations <= 63u && c->corotated <= 1u
                 ? 0
                 : SC_ERR_CAN_SIGNAL;
    put_u(f, m, 2u, c->label & 0xFu);
    put_u(f, m, 3u, c->cg_iterations & 0x3Fu);
    put_u(f, m, 4u, c->corotated & 1u);
    if (rc == 0) {
        rc = put_phys(f, m, 5u, c->e_kpa);
    }
    if (rc == 0) {
        rc = put_phys(f, m, 6u, c->poisson);
    }
    if (rc == 0) {
        rc = put_phys(f, m, 7u, c->damping_s);
    }
    for (unsigned i = 2u; i <= 7u && rc == 0; i++) {
        rc = in_range(f, m, i) ? 0 : SC_ERR_CAN_SIGNAL;
    }
    return rc;
}

int sc_canproto_encode_cmd(const sc_cmd *c, uint8_t counter, sc_can_frame *out)
{
    int rc = 0;
    sc_msg m;
    switch (c->kind) {
    case SC_CMD_SELECT_CASE:
        m = SC_MSG_CMD_CASE;
        frame_begin(out, m);
        rc = c->case_id <= 254u ? 0 : SC_ERR_CAN_SIGNAL;
        put_u(out, m, 2u, c->case_id);
        break;
    case SC_CMD_SET_METHOD:
        m = SC_MSG_CMD_METHOD;
        frame_begin(out, m);
        rc = c->method <= SC_METHOD_FEM ? 0 : SC_ERR_CAN_SIGNAL;
        put_u(out, m, 2u, c->method);
        break;
    case SC_CMD_SET_IMAGING:
        m = SC_MSG_CMD_IMAGING;
        frame_begin(out, m);
        rc = put_phys(out, m, 2u, c->imaging.depth_mm);
        if (rc == 0) {
            rc = put_phys(out, m, 3u, c->imaging.gain_db);
        }
        if (rc == 0) {
            rc = put_phys(out, m, 4u, c->imaging.dyn_range_db);
        }
        if (rc == 0) {
            rc = put_phys(out, m, 5u, c->imaging.tgc_db_per_cm);
        }
        if (rc == 0) {
            rc = c->imaging.geometry <= SC_SCAN_CURVILINEAR ? 0 : SC_ERR_CAN_SIGNAL;
            put_u(out, m, 6u, c->imaging.geometry & 3u);
        }
        for (unsigned i = 2u; i <= 6u && rc == 0; i++) {
            rc = in_range(out, m, i) ? 0 : SC_ERR_CAN_SIGNAL;
        }
        break;
    case SC_CMD_RESET:
        m = SC_MSG_CMD_RESET;
        frame_begin(out, m);
        rc = c->reset_target >= SC_RESET_TISSUE && c->reset_target <= SC_RESET_ALL
                 ? 0
                 : SC_ERR_CAN_SIGNAL;
        put_u(out, m, 2u, c->reset_target & 3u);
        break;
    case SC_CMD_SYNC_FRESHNESS:
        m = SC_MSG_CMD_SYNC;
        frame_begin(out, m);
        rc = c->fv_high < ((uint64_t)1 << 48) ? 0 : SC_ERR_CAN_SIGNAL;
        put_u(out, m, 2u, (uint32_t)(c->fv_high & 0xFFFFFFu));
        put_u(out, m, 3u, (uint32_t)((c->fv_high >> 24) & 0xFFFFFFu));
        break;
    case SC_CMD_ASSESS:
        m = SC_MSG_CMD_ASSESS;
        frame_begin(out, m);
        rc = assess_pair_ok(c->assess_action, c->assess_call) ? 0 : SC_ERR_CAN_SIGNAL;
        put_u(out, m, 2u, c->assess_action & 3u);
        put_u(out, m, 3u, c->assess_call & 3u);
        break;
    case SC_CMD_VESSELS:
        m = SC_MSG_CMD_VESSELS;
        frame_begin(out, m);
        rc = c->vessels.valsalva <= 1u && c->vessels.pulse <= 1u ? 0 : SC_ERR_CAN_SIGNAL;
        if (rc == 0) {
            rc = put_phys(out, m, 2u, c->vessels.heart_rate_bpm);
        }
        if (rc == 0) {
            rc = put_phys(out, m, 3u, c->vessels.resp_rate_bpm);
        }
        put_u(out, m, 4u, c->vessels.valsalva & 1u);
        put_u(out, m, 5u, c->vessels.pulse & 1u);
        for (unsigned i = 2u; i <= 3u && rc == 0; i++) {
            rc = in_range(out, m, i) ? 0 : SC_ERR_CAN_SIGNAL;
        }
        break;
    case SC_CMD_DOPPLER:
        m = SC_MSG_CMD_DOPPLER;
        frame_begin(out, m);
        rc = c->doppler.on <= 1u ? 0 : SC_ERR_CAN_SIGNAL;
        put_u(out, m, 2u, c->doppler.on & 1u);
        if (rc == 0) {
            rc = put_phys(out, m, 3u, c->doppler.prf_hz);
        }
        if (rc == 0) {
            rc = put_phys(out, m, 4u, c->doppler.steer_deg);
        }
        if (rc == 0) {
            rc = put_phys(out, m, 5u, c->doppler.gain_db);
        }
        for (unsigned i = 3u; i <= 5u && rc == 0; i++) {
            rc = in_range(out, m, i) ? 0 : SC_ERR_CAN_SIGNAL;
        }
        break;
    case SC_CMD_MATERIAL:
        m = SC_MSG_CMD_MATERIAL;
        frame_begin(out, m);
        rc = encode_material(out, m, &c->material);
        break;
    default:
        return SC_ERR_INVALID_ARG;
    }
    if (rc != 0) {
        return rc;
    }
    return protect(out, m, counter);
}

int sc_canproto_decode_cmd(const sc_can_frame *f, sc_cmd *out)
{
    sc_msg m;
    int rc = sc_canproto_classify(f, &m);
    if (rc != 0) {
        return rc;
    }
    sc_cmd c = {0};
    unsigned nsig = 0;
    switch (m) {
    case SC_MSG_CMD_CASE:
        c.kind = SC_CMD_SELECT_CASE;
        c.case_id = (uint8_t)get_u(f, m, 2u);
        nsig = 1;
        break;
    case SC_MSG_CMD_METHOD:
        c.kind = SC_CMD_SET_METHOD;
        c.method = (uint8_t)get_u(f, m, 2u);
        nsig = 1;
        break;
    case SC_MSG_CMD_IMAGING:
        c.kind = SC_CMD_SET_IMAGING;
        c.imaging.depth_mm = get_phys(f, m, 2u);
        c.imaging.gain_db = get_phys(f, m, 3u);
        c.imaging.dyn_range_db = get_phys(f, m, 4u);
        c.imaging.tgc_db_per_cm = get_phys(f, m, 5u);
        c.imaging.geometry = (uint8_t)get_u(f, m, 6u);
        nsig = 5;
        break;
    case SC_MSG_CMD_RESET:
        c.kind = SC_CMD_RESET;
        c.reset_target = (uint8_t)get_u(f, m, 2u);
        nsig = 1;
        break;
    case SC_MSG_CMD_SYNC:
        c.kind = SC_CMD_SYNC_FRESHNESS;
        c.fv_high = (uint64_t)get_u(f, m, 2u) | ((uint64_t)get_u(f, m, 3u) << 24);
        nsig = 0;
        break;
    case SC_MSG_CMD_ASSESS:
        c.kind = SC_CMD_ASSESS;
        c.assess_action = (uint8_t)get_u(f, m, 2u);
        c.assess_call = (uint8_t)get_u(f, m, 3u);
        if (!assess_pair_ok(c.assess_action, c.assess_call)) {
            return SC_ERR_CAN_SIGNAL;
        }
        nsig = 2;
        break;
    case SC_MSG_CMD_VESSELS:
        c.kind = SC_CMD_VESSELS;
        c.vessels.heart_rate_bpm = get_phys(f, m, 2u);
        c.vessels.resp_rate_bpm = get_phys(f, m, 3u);
        c.vessels.valsalva = (uint8_t)get_u(f, m, 4u);
        c.vessels.pulse = (uint8_t)get_u(f, m, 5u);
        nsig = 4;
        break;
    case SC_MSG_CMD_DOPPLER:
        c.kind = SC_CMD_DOPPLER;
        c.doppler.on = (uint8_t)get_u(f, m, 2u);
        c.doppler.prf_hz = get_phys(f, m, 3u);
        c.doppler.steer_deg = get_phys(f, m, 4u);
        c.doppler.gain_db = get_phys(f, m, 5u);
        nsig = 4;
        break;
    case SC_MSG_CMD_MATERIAL:
        c.kind = SC_CMD_MATERIAL;
        c.material.label = (uint8_t)get_u(f, m, 2u);
        c.material.cg_iterations = (uint8_t)get_u(f, m, 3u);
        c.material.corotated = (uint8_t)get_u(f, m, 4u);
        c.material.e_kpa = get_phys(f, m, 5u);
        c.material.poisson = get_phys(f, m, 6u);
        c.material.damping_s = get_phys(f, m, 7u);
        nsig = 6;
        break;
    case SC_MSG_POSE_POS:
    case SC_MSG_POSE_QUAT:
    case SC_MSG_POSE_AUX:
    case SC_MSG_POSE_FD:
    case SC_MSG_STATUS:
    case SC_MSG_TIMING:
    case SC_MSG_DIAG:
    case SC_MSG_AUTH_DIAG:
    case SC_MSG_AUTH_CASE:
    case SC_MSG_AUTH_METHOD:
    case SC_MSG_AUTH_IMAGING:
    case SC_MSG_AUTH_RESET:
    case SC_MSG_AUTH_SYNC:
    case SC_MSG_AUTH_ASSESS:
    case SC_MSG_AUTH_VESSELS:
    case SC_MSG_AUTH_DOPPLER:
    case SC_MSG_AUTH_MATERIAL:
    case SC_MSG_ASSESS_VESSELS:
    case SC_MSG_ASSESS_FORCE:
    case SC_MSG_ASSESS_SCORE:

    case SC_MSG_NEEDLE_POS:
    case SC_MSG_NEEDLE_DIR:
    case SC_MSG_NEEDLE_AUX:
    case SC_MSG_NEEDLE_STATUS:
    case SC_MSG_COUNT:
        return SC_ERR_CAN_ID;
    }
    for (unsigned i = 0; i < nsig; i++) {
        if (!in_range(f, m, 2u + i)) {
            return SC_ERR_CAN_SIGNAL;
        }
    }
    *out = c;
    return 0;
}

/* ---- status -------------------------------------------------------------------------------- */

static int put_ratio(sc_can_frame *f, sc_msg m, unsigned idx, float r)
{
    if (!isfinite(r)) {
        return SC_ERR_NOT_FINITE;
    }
    if (r < 0.0f) {
        put_u(f, m, idx, 0xFFFFu);
        return 0;
    }
    const float max = sig_of(m, idx)->max;
    return put_phys(f, m, idx, r > max ? max : r);
}

int sc_canproto_encode_status(const sc_status_msg *s, sc_e2e_tx tx[SC_STATUS_FRAMES],
                              sc_can_frame out[SC_STATUS_FRAMES])
{
    if (s->state > 3u || s->method > SC_METHOD_FEM) {
        return SC_ERR_CAN_SIGNAL;
    }
    sc_msg m = SC_MSG_STATUS;
    frame_begin(&out[0], m);
    put_u(&out[0], m, 2u, s->state);
    put_u(&out[0], m, 3u, s->method);
    put_u(&out[0], m, 4u, s->probe_contact ? 1u : 0u);
    put_u(&out[0], m, 5u, s->probe_lifted ? 1u : 0u);
    put_u(&out[0], m, 6u, s->fault_bits);
    put_u(&out[0], m, 7u, sat_u(s->deadline_misses, 0xFFFFu));
    put_u(&out[0], m, 8u, s->case_id);

    m = SC_MSG_TIMING;
    frame_begin(&out[1], m);
    put_u(&out[1], m, 2u, sat_u(s->worst_frame_us, 0xFFFFu));
    int rc = put_ratio(&out[1], m, 3u, s->vein_area_ratio);
    if (rc == 0) {
        rc = put_ratio(&out[1], m, 4u, s->artery_area_ratio);
    }
    if (rc != 0) {
        return rc;
    }

    m = SC_MSG_DIAG;
    frame_begin(&out[2], m);
    put_u(&out[2], m, 2u, s->poses_accepted & 0xFFFFu);
    put_u(&out[2], m, 3u, sat_u(s->rejected_e2e, 0xFFFFu));
    put_u(&out[2], m, 4u, sat_u(s->rejected_plausibility, 0xFFu));
    put_u(&out[2], m, 5u, sat_u(s->lift_events, 0xFFu));

    m = SC_MSG_AUTH_DIAG;
    frame_begin(&out[3], m);
    put_u(&out[3], m, 2u, s->cmds_authenticated & 0xFFFFu);
    put_u(&out[3], m, 3u, sat_u(s->auth_rejected, 0xFFFFu));
    put_u(&out[3], m, 4u, sat_u(s->auth_bad_mac, 0xFFu));
    put_u(&out[3], m, 5u, sat_u(s->auth_stale, 0xFFu));

    for (unsigned i = 0; i < SC_STATUS_FRAMES; i++) {
        rc = sc_e2e_protect(&tx[i], out[i].data, out[i].len);
        if (rc != 0) {
            return rc;
        }
    }
    return 0;
}

static float get_ratio(const sc_can_frame *f, sc_msg m, unsigned idx)
{
    return get_u(f, m, idx) == 0xFFFFu ? SC_AREA_RATIO_NOT_AVAILABLE : get_phys(f, m, idx);
}

int sc_canproto_decode_status_part(const sc_can_frame *f, sc_status_msg *s)
{
    sc_msg m;
    int rc = sc_canproto_classify(f, &m);
    if (rc != 0) {
        return rc;
    }
    switch (m) {
    case SC_MSG_STATUS:
        s->state = (uint8_t)get_u(f, m, 2u);
        s->method = (uint8_t)get_u(f, m, 3u);
        s->probe_contact = (uint8_t)get_u(f, m, 4u);
        s->probe_lifted = (uint8_t)get_u(f, m, 5u);
        s->fault_bits = (uint16_t)get_u(f, m, 6u);
        s->deadline_misses = get_u(f, m, 7u);
        s->case_id = (uint8_t)get_u(f, m, 8u);
        return 0;
    case SC_MSG_TIMING:
        s->worst_frame_us = get_u(f, m, 2u);
        s->vein_area_ratio = get_ratio(f, m, 3u);
        s->artery_area_ratio = get_ratio(f, m, 4u);
        return 0;
    case SC_MSG_DIAG:
        s->poses_accepted = get_u(f, m, 2u);
        s->rejected_e2e = get_u(f, m, 3u);
        s->rejected_plausibility = get_u(f, m, 4u);
        s->lift_events = get_u(f, m, 5u);
        return 0;
    case SC_MSG_AUTH_DIAG:
        s->cmds_authenticated = get_u(f, m, 2u);
        s->auth_rejected = get_u(f, m, 3u);
        s->auth_bad_mac = get_u(f, m, 4u);
        s->auth_stale = get_u(f, m, 5u);
        return 0;
    case SC_MSG_CMD_CASE:
    case SC_MSG_CMD_METHOD:
    case SC_MSG_CMD_IMAGING:
    case SC_MSG_CMD_RESET:
    case SC_MSG_CMD_SYNC:
    case SC_MSG_CMD_ASSESS:
    case SC_MSG_CMD_VESSELS:
    case SC_MSG_CMD_DOPPLER:
    case SC_MSG_CMD_MATERIAL:
    case SC_MSG_POSE_POS:
    case SC_MSG_POSE_QUAT:
    case SC_MSG_POSE_AUX:
    case SC_MSG_POSE_FD:
    case SC_MSG_AUTH_CASE:
    case SC_MSG_AUTH_METHOD:
    case SC_MSG_AUTH_IMAGING:
    case SC_MSG_AUTH_RESET:
    case SC_MSG_AUTH_SYNC:
    case SC_MSG_AUTH_ASSESS:
    case SC_MSG_AUTH_VESSELS:
    case SC_MSG_AUTH_DOPPLER:
    case SC_MSG_AUTH_MATERIAL:
    case SC_MSG_ASSESS_VESSELS:
    case SC_MSG_ASSESS_FORCE:
    case SC_MSG_ASSESS_SCORE:
    case SC_MSG_NEEDLE_POS:
    case SC_MSG_NEEDLE_DIR:
    case SC_MSG_NEEDLE_AUX:
    case SC_MSG_NEEDLE_STATUS:
    case SC_MSG_COUNT:
        break;
    }
    return SC_ERR_CAN_ID;
}

/* ---- assessment ---------------------------------------------------------------------------- */

/* A ratio or force field: negative = not available (0xFFFF), else clamped to the field. */
static int put_avail(sc_can_frame *f, sc_msg m, unsigned idx, float v)
{
    return put_ratio(f, m, idx, v);
}

int sc_canproto_encode_assess(const sc_assess_msg *a, sc_e2e_tx tx[SC_ASSESS_FRAMES],
                              sc_can_frame out[SC_ASSESS_FRAMES])
{
    if (a->call > SC_ASSESS_CALL_DVT || a->finding > SC_ASSESS_CALL_DVT) {
        return SC_ERR_CAN_SIGNAL;
    }
    int rc = 0;
    sc_msg m = SC_MSG_ASSESS_VESSELS;
    frame_begin(&out[0], m);
    for (unsigned v = 0; v < SC_ASSESS_VESSELS && rc == 0; v++) {
        rc = put_avail(&out[0], m, 2u + v, a->min_ratio[v]);
    }
    m = SC_MSG_ASSESS_FORCE;
    frame_begin(&out[1], m);
    for (unsigned v = 0; v < SC_ASSESS_VESSELS && rc == 0; v++) {
        rc = put_avail(&out[1], m, 2u + v, a->force_at_min_n[v]);
    }
    m = SC_MSG_ASSESS_SCORE;
    frame_begin(&out[2], m);
    if (rc == 0) {
        rc = put_avail(&out[2], m, 2u, a->peak_force_n);
    }
    if (rc != 0) {
        return rc;
    }
    for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
        put_u(&out[2], m, 3u + v, a->coapted[v] ? 1u : 0u);
    }
    put_u(&out[2], m, 6u, a->artery_over ? 1u : 0u);
    put_u(&out[2], m, 7u, a->call);
    put_u(&out[2], m, 8u, a->finding);
    put_u(&out[2], m, 9u, a->criteria_met);
    put_u(&out[2], m, 10u, a->score);
    put_u(&out[2], m, 11u, a->score_max);
    put_u(&out[2], m, 12u, a->artery_punctured ? 1u : 0u);
    put_u(&out[2], m, 13u, a->vein_punctured ? 1u : 0u);
    for (unsigned i = 0; i < SC_ASSESS_FRAMES; i++) {
        rc = sc_e2e_protect(&tx[i], out[i].data, out[i].len);
        if (rc != 0) {
            return rc;
        }
    }
    return 0;
}

int sc_canproto_decode_assess_part(const sc_can_frame *f, sc_assess_msg *a)
{
    sc_msg m;
    int rc = sc_canproto_classify(f, &m);
    if (rc != 0) {
        return rc;
    }
    if (m == SC_MSG_ASSESS_VESSELS) {
        for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
            a->min_ratio[v] = get_ratio(f, m, 2u + v);
        }
        return 0;
    }
    if (m == SC_MSG_ASSESS_FORCE) {
        for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
            a->force_at_min_n[v] = get_ratio(f, m, 2u + v);
        }
        return 0;
    }
    if (m == SC_MSG_ASSESS_SCORE) {
        a->peak_force_n = get_ratio(f, m, 2u);
        for (unsigned v = 0; v < SC_ASSESS_VESSELS; v++) {
            a->coapted[v] = (uint8_t)get_u(f, m, 3u + v);
        }
        a->artery_over = (uint8_t)get_u(f, m, 6u);
        a->call = (uint8_t)get_u(f, m, 7u);
        a->finding = (uint8_t)get_u(f, m, 8u);
        a->criteria_met = (uint8_t)get_u(f, m, 9u);
        a->score = (uint8_t)get_u(f, m, 10u);
        a->score_max = (uint8_t)get_u(f, m, 11u);
        a->artery_punctured = (uint8_t)get_u(f, m, 12u);
        a->vein_punctured = (uint8_t)get_u(f, m, 13u);
        return 0;
    }
    return SC_ERR_CAN_ID;
}
/* ---- needle -------------------------------------------------------------------------------- */

int sc_canproto_encode_needle(const sc_needle_msg *m, uint8_t counter, sc_can_frame *out,
                              size_t cap, size_t *n)
{
    *n = 0u;
    if (cap < 3u) {
        return SC_ERR_NO_SPACE;
    }
    int rc = 0;
    frame_begin(&out[0], SC_MSG_NEEDLE_POS);
    frame_begin(&out[1], SC_MSG_NEEDLE_DIR);
    frame_begin(&out[2], SC_MSG_NEEDLE_AUX);
    for (unsigned i = 0; i < 3u && rc == 0; i++) {
        rc = put_phys(&out[0], SC_MSG_NEEDLE_POS, 2u + i, m->tip_mm[i]);
    }
    for (unsigned i = 0; i < 3u && rc == 0; i++) {
        rc = put_phys(&out[1], SC_MSG_NEEDLE_DIR, 2u + i, m->dir[i]);
    }
    if (rc == 0) {
        rc = put_phys(&out[2], SC_MSG_NEEDLE_AUX, 2u, m->depth_mm);
    }
    if (rc == 0) {
        if (m->tracking > 1u) {
            return SC_ERR_CAN_SIGNAL;
        }
        put_u(&out[2], SC_MSG_NEEDLE_AUX, 3u, m->tracking);
    }
    for (unsigned i = 0; i < 3u && rc == 0; i++) {
        rc = protect(&out[i], (sc_msg)((unsigned)SC_MSG_NEEDLE_POS + i), counter);
    }
    *n = rc == 0 ? 3u : 0u;
    return rc;
}

int sc_canproto_decode_needle_part(const sc_can_frame *f, sc_needle_msg *m)
{
    sc_msg msg;
    const int rc = sc_canproto_classify(f, &msg);
    if (rc != 0) {
        return rc;
    }
    if (msg == SC_MSG_NEEDLE_POS) {
        for (unsigned i = 0; i < 3u; i++) {
            m->tip_mm[i] = get_phys(f, msg, 2u + i);
        }
        return 1;
    }
    if (msg == SC_MSG_NEEDLE_DIR) {
        for (unsigned i = 0; i < 3u; i++) {
            m->dir[i] = get_phys(f, msg, 2u + i);
        }
        return 2;
    }
    if (msg == SC_MSG_NEEDLE_AUX) {
        m->depth_mm = get_phys(f, msg, 2u);
        m->tracking = (uint8_t)get_u(f, msg, 3u);
        return 4;
    }
    return SC_ERR_CAN_ID;
}

int sc_canproto_encode_needle_status(const sc_needle_status_msg *s, uint8_t counter,
                                     sc_can_frame *out)
{
    const sc_msg m = SC_MSG_NEEDLE_STATUS;
    frame_begin(out, m);
    put_u(out, m, 2u, sat_u(s->tip_vessel, 15u));
    put_u(out, m, 3u, s->needle_tracked ? 1u : 0u);
    put_u(out, m, 4u, sat_u(s->last_puncture, 15u));
    put_u(out, m, 5u, s->vein_punctures);
    put_u(out, m, 6u, s->artery_punctures);
    put_u(out, m, 7u, s->needle_rejected);
    return protect(out, m, counter);
}

int sc_canproto_decode_needle_status(const sc_can_frame *f, sc_needle_status_msg *s)
{
    sc_msg m;
    const int rc = sc_canproto_classify(f, &m);
    if (rc != 0) {
        return rc;
    }
    if (m != SC_MSG_NEEDLE_STATUS) {
        return SC_ERR_CAN_ID;
    }
    s->tip_vessel = (uint8_t)get_u(f, m, 2u);
    s->needle_tracked = (uint8_t)get_u(f, m, 3u);
    s->last_puncture = (uint8_t)get_u(f, m, 4u);
    s->vein_punctures = (uint8_t)get_u(f, m, 5u);
    s->artery_punctures = (uint8_t)get_u(f, m, 6u);
    s->needle_rejected = (uint16_t)get_u(f, m, 7u);
    return 0;
}
