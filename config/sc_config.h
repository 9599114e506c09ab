/*
 * sc_config.h: compile-time limits and defaults of the engine.
 *
 * Every capacity of the engine object comes from here. Each is an #ifndef default so that a
 * target overrides it from its build (the cortex-m7 image shrinks them to fit its RAM). A case
 * or setting above a limit is refused at load time with a named error, never at frame time.
 * Units are in the names.
 */
#ifndef SC_CONFIG_H
#define SC_CONFIG_H

/* ---- frame scheduler -------------------------------------------------------------------- */
#ifndef SC_FRAME_RATE_DEFAULT_HZ
#define SC_FRAME_RATE_DEFAULT_HZ 60u
#endif
#ifndef SC_FRAME_RATE_MIN_HZ
#define SC_FRAME_RATE_MIN_HZ 1u
#endif
#ifndef SC_FRAME_RATE_MAX_HZ
#define SC_FRAME_RATE_MAX_HZ 240u
#endif
#ifndef SC_SCHED_MAX_STAGES
#define SC_SCHED_MAX_STAGES 8u
#endif
/* A burst of deadline misses is logged as its first miss, then at most one line per interval
 * (the misses in between are counted in that line: the log must not flood under overload;
 * the exact total is in the status). */
#ifndef SC_ENGINE_MISS_LOG_INTERVAL_NS
#define SC_ENGINE_MISS_LOG_INTERVAL_NS 1000000000u
#endif
/* Frames with deadline misses among the last SC_HEALTH_MISS_WINDOW frames that make the
 * engine DEGRADED. */
#ifndef SC_HEALTH_MISS_WINDOW
#define SC_HEALTH_MISS_WINDOW 64u
#endif
#ifndef SC_HEALTH_MISS_DEGRADED
#define SC_HEALTH_MISS_DEGRADED 4u
#endif

/* ---- soft-tissue mesh (paper Table I: up to 32x16x16 nodes; the appliance up to 64x32x32:
 * 63 MB per tissue slot and 137 MB of engine object, mostly untouched below that size) ----- */
#ifndef SC_MAX_MESH_NX
#define SC_MAX_MESH_NX 64u
#endif
#ifndef SC_MAX_MESH_NY
#define SC_MAX_MESH_NY 32u
#endif
#ifndef SC_MAX_MESH_NZ
#define SC_MAX_MESH_NZ 32u
#endif
#ifndef SC_MAX_NODES
#define SC_MAX_NODES (SC_MAX_MESH_NX * SC_MAX_MESH_NY * SC_MAX_MESH_NZ)
#endif
/* 5 tets per cube of the grid. */
#ifndef SC_MAX_TETS
#define SC_MAX_TETS (5u * (SC_MAX_MESH_NX - 1u) * (SC_MAX_MESH_NY - 1u) * (SC_MAX_MESH_NZ - 1u))
#endif
/* Physics iterations per frame and time step (paper section VI: 20 and 0.01 s). */
/* Vessel lumens as pressure-volume chambers with a cardiac/respiratory drive
 * (core/physics/sc_lumen.h; one byte per tet). 0: vessels are solid filler only. */
#ifndef SC_PHYS_LUMEN
#define SC_PHYS_LUMEN 1
#endif
#ifndef SC_PHYS_ITERATIONS_DEFAULT
#define SC_PHYS_ITERATIONS_DEFAULT 20u
#endif
#ifndef SC_PHYS_ITERATIONS_MAX
#define SC_PHYS_ITERATIONS_MAX 200u
#endif
/* CG iterations per frame of the implicit step (FEM and the stable MSDS; sc_fem.h). The
 * frame's simulated time stays SC_PHYS_ITERATIONS_DEFAULT x dt. */
#ifndef SC_PHYS_CG_ITERATIONS_DEFAULT
#define SC_PHYS_CG_ITERATIONS_DEFAULT 10u
#endif
#ifndef SC_PHYS_DT_DEFAULT_S
#define SC_PHYS_DT_DEFAULT_S 0.01f
#endif
/* FEM 3x3 blocks (sc_fem.h, upper triangle): in the 5-tet grid a node of odd i+j+k has at
 * most 18 neighbours (6 axis + 12 face diagonals), 9 of them with a larger index, plus itself:
 * 10 blocks; an even node 6 neighbours: 4 blocks; at most (N + 1) / 2 nodes are odd:
 * 10 (N + 1) / 2 + 4 (N + 1) / 2 = 7 (N + 1). */
#ifndef SC_MAX_FEM_NNZ_BLOCKS
#define SC_MAX_FEM_NNZ_BLOCKS (7u * (SC_MAX_NODES + 1u))
#endif
/* MSDS springs (sc_springs.h, Algorithm 1): the 5-tet grid has one spring per grid edge
 * (3 per node) and one per grid face diagonal (3 per node): at most 6 N. */
#ifndef SC_MAX_SPRINGS
#define SC_MAX_SPRINGS (6u * SC_MAX_NODES)
#endif
/* log2 of the build-time spring hash table (>= 2 SC_MAX_SPRINGS slots): the smallest that
 * fits, so that a target with smaller mesh limits gets a smaller table. */
#ifndef SC_SPRINGS_HASH_BITS
#if SC_MAX_SPRINGS <= 512u
#define SC_SPRINGS_HASH_BITS 10u
#elif SC_MAX_SPRINGS <= 2048u
#define SC_SPRINGS_HASH_BITS 12u
#elif SC_MAX_SPRINGS <= 8192u
#define SC_SPRINGS_HASH_BITS 14u
#elif SC_MAX_SPRINGS <= 32768u
#define SC_SPRINGS_HASH_BITS 16u
#elif SC_MAX_SPRINGS <= 65536u
#define SC_SPRINGS_HASH_BITS 17u
#else
#define SC_SPRINGS_HASH_BITS 20u
#endif
#endif
/* Skin surface (sc_skin.h): a regular triangle grid over the top of the mesh box. */
#ifndef SC_MAX_SKIN_NX
#define SC_MAX_SKIN_NX 64u
#endif
#ifndef SC_MAX_SKIN_NY
#define SC_MAX_SKIN_NY 64u
#endif
#ifndef SC_MAX_SKIN_NODES
#define SC_MAX_SKIN_NODES (SC_MAX_SKIN_NX * SC_MAX_SKIN_NY)
#endif
/* Probe contacts per body (sc_collider.h): at most one per node of the tet mesh or skin. */
#ifndef SC_MAX_CONTACTS
#define SC_MAX_CONTACTS (SC_MAX_NODES > SC_MAX_SKIN_NODES ? SC_MAX_NODES : SC_MAX_SKIN_NODES)
#endif
_Static_assert((1u << SC_SPRINGS_HASH_BITS) >= 2u * SC_MAX_SPRINGS,
               "spring hash table below twice the spring capacity");

/* ---- labels and materials --------------------------------------------------------------- */
#ifndef SC_MAX_LABELS
#define SC_MAX_LABELS 16u
#endif

/* ---- case volume (read through hal storage, not copied) ---------------------------------- */
#ifndef SC_MAX_VOLUME_DIM
#define SC_MAX_VOLUME_DIM 1024u
#endif
#ifndef SC_MAX_VOLUME_VOXELS
#define SC_MAX_VOLUME_VOXELS (256u * 1024u * 1024u)
#endif

/* ---- B-scan image ----------------------------------------------------------------------- */
#ifndef SC_MAX_SCAN_LINES
#define SC_MAX_SCAN_LINES 512u
#endif
#ifndef SC_MAX_SCAN_SAMPLES
#define SC_MAX_SCAN_SAMPLES 512u
#endif

/* ---- B-scan synthesis (sc_bscan) --------------------------------------------------------- */
/* Speckle from a scatterer field and the beam's PSF (core/imaging/sc_psf.h): its lines in
 * flight cost 13 x SC_MAX_SCAN_SAMPLES x 10 B (66 KiB at 512 samples, 16.6 KiB at the MCU's
 * 128); 0 leaves it out (sc_bscan_def.psf = 1 is then rejected). */
#ifndef SC_BSCAN_PSF
#define SC_BSCAN_PSF 1
#endif
/* Image regions of the paper's fast path (section IV: R = 32 measured best). */
#ifndef SC_BSCAN_REGIONS_DEFAULT
#define SC_BSCAN_REGIONS_DEFAULT 32u
#endif
#ifndef SC_BSCAN_MAX_REGIONS
#define SC_BSCAN_MAX_REGIONS 64u
#endif
/* Time-gain compensation depth bands. */
#ifndef SC_BSCAN_TGC_BANDS
#define SC_BSCAN_TGC_BANDS 8u
#endif
/* Boundary triangles of the tet mesh (2 per boundary quad of the box). */
#ifndef SC_BSCAN_MAX_HULL_FACES
#define SC_BSCAN_MAX_HULL_FACES                                                                \
    (4u * ((SC_MAX_MESH_NX - 1u) * (SC_MAX_MESH_NY - 1u) +                                     \
           (SC_MAX_MESH_NX - 1u) * (SC_MAX_MESH_NZ - 1u) +                                     \
           (SC_MAX_MESH_NY - 1u) * (SC_MAX_MESH_NZ - 1u)))
#endif
/* Tets cut by the image plane kept by the region (paper) path; a plane through the default
 * 32x16x16 mesh cuts about 2,300 of them. Above it that path falls back to the walker. */
#ifndef SC_BSCAN_MAX_PLANE_TETS
#define SC_BSCAN_MAX_PLANE_TETS (SC_MAX_TETS / 4u)
#endif
#ifndef SC_BSCAN_MAX_REGION_REFS
#define SC_BSCAN_MAX_REGION_REFS (4u * SC_BSCAN_MAX_PLANE_TETS)
#endif
/* Mesh-boundary crossings kept per scan line, and tet steps of the walker per scan line. */
#ifndef SC_BSCAN_MAX_LINE_EVENTS
#define SC_BSCAN_MAX_LINE_EVENTS 64u
#endif
#ifndef SC_BSCAN_MAX_WALK_STEPS
#define SC_BSCAN_MAX_WALK_STEPS 4096u
#endif
/* The B-scan's lines on the worker pool (sc_bscan_set_pool): ranges of lines with their own
 * scratch (1: no pool path, the MCU's setting). Per range: the runs of its lines kept for the
 * line hook until they leave in order (SC_BSCAN_RANGE_RUNS, 28 B each; a range that would
 * overflow them hands its remaining lines to the caller) and the walker's active boundary
 * segments (SC_BSCAN_RANGE_ACTIVE, 4 B each; the same). With more than one range the frame's
 * displayed samples and labels are kept too (2 x SC_MAX_SCAN_LINES x SC_MAX_SCAN_SAMPLES B).
 * The runs: with the engine's line hook on (colour Doppler, the needle) a range keeps every line's
 * runs, up to one per sample: 32 lines of 512 samples (the default 256 lines in 8 ranges) need
 * 16,384 (a range stops when its kept runs and one more line's worst case would not fit: with
 * 4,096, past 3,584 kept runs). Host default: 8 ranges, about 4.3 MB in all. */
#ifndef SC_BSCAN_RANGES
#define SC_BSCAN_RANGES 8u
#endif
#ifndef SC_BSCAN_RANGE_RUNS
#define SC_BSCAN_RANGE_RUNS 16384u
#endif
#ifndef SC_BSCAN_RANGE_ACTIVE
#define SC_BSCAN_RANGE_ACTIVE 1024u
#endif

/* ---- runtime configuration file (sc_rtcfg) ----------------------------------------------- */
/* Longest line of the configuration file, and longest path or host value, in bytes. */
#ifndef SC_RTCFG_LINE_MAX
#define SC_RTCFG_LINE_MAX 512u
#endif
#ifndef SC_RTCFG_PATH_MAX
#define SC_RTCFG_PATH_MAX 256u
#endif

/* ---- CAN --------------------------------------------------------------------------------- */
/* Frames drained from the CAN receive queue per frame, at most (bounds the rx stage). */
#ifndef SC_CAN_RX_BURST_MAX
#define SC_CAN_RX_BURST_MAX 64u
#endif
#ifndef SC_CAN_MAX_FILTERS
#define SC_CAN_MAX_FILTERS 16u
#endif
/* Decoded CAN commands waiting for the engine (sc_tracker); more in one frame are dropped
 * and counted. */
#ifndef SC_CAN_CMD_QUEUE_MAX
#define SC_CAN_CMD_QUEUE_MAX 8u
#endif
_Static_assert(SC_CAN_CMD_QUEUE_MAX >= 1u && SC_CAN_CMD_QUEUE_MAX <= 255u,
               "command queue length must fit uint8_t");
/* Command authentication (core/link/sc_secoc.h): senders whose freshness the engine keeps
 * (ids 0 .. SC_SECOC_SENDERS - 1; 24 bytes each), and how long a command waits for its
 * cryptographic PDU (sent back to back: 50 ms is 20 frame times at a loaded 500 kbit/s). */
#ifndef SC_SECOC_SENDERS
#define SC_SECOC_SENDERS 4u
#endif
_Static_assert(SC_SECOC_SENDERS >= 1u && SC_SECOC_SENDERS <= 16u, "4-bit sender ids");
#ifndef SC_TRK_AUTH_PAIR_MS
#define SC_TRK_AUTH_PAIR_MS 50u
#endif
_Static_assert(SC_TRK_AUTH_PAIR_MS >= 1u && SC_TRK_AUTH_PAIR_MS <= 1000u,
               "a command waits 1 .. 1000 ms for its MAC");
/* Clock readings per estimate of the SocketCAN time stamp offset (REALTIME -> MONOTONIC,
 * platform/linux/sc_socketcan.h); the narrowest bracket wins. In the HIL VM under TCG the
 * readings were 0.4-0.5 us wide on average, the widest of ~1100 per run 2-139 us (preempted):
 * one of 8 is narrow all but always. */
#ifndef SC_SOCKETCAN_CLOCK_READINGS
#define SC_SOCKETCAN_CLOCK_READINGS 8u
#endif
_Static_assert(SC_SOCKETCAN_CLOCK_READINGS >= 1u && SC_SOCKETCAN_CLOCK_READINGS <= 64u,
               "1..64 clock readings per time stamp offset estimate");

/* ---- vessel cues (issue 18): colour/spectral Doppler and the tracked needle ---- */
/* 1: the engine carries colour and pulsed-wave Doppler (core/imaging/sc_doppler.h); 0 leaves
 * it out (an MCU short of RAM): the engine then sends B-mode only. */
#ifndef SC_ENABLE_DOPPLER
#define SC_ENABLE_DOPPLER 1
#endif
/* Bins of the pulsed-wave spectrum column sent with each frame (<= 128, the display link's). */
#ifndef SC_DOPPLER_SPECTRUM_BINS
#define SC_DOPPLER_SPECTRUM_BINS 128u
#endif
/* 1: the tracked needle (second tool on CAN, drawn in the B-scan, puncture reports). */
#ifndef SC_ENABLE_NEEDLE
#define SC_ENABLE_NEEDLE 1
#endif
_Static_assert(SC_DOPPLER_SPECTRUM_BINS >= 8u && SC_DOPPLER_SPECTRUM_BINS <= 128u,
               "8..128 spectrum bins");

_Static_assert(SC_FRAME_RATE_DEFAULT_HZ >= SC_FRAME_RATE_MIN_HZ &&
                   SC_FRAME_RATE_DEFAULT_HZ <= SC_FRAME_RATE_MAX_HZ,
               "default frame rate outside its range");
_Static_assert(SC_MAX_MESH_NX >= 2u && SC_MAX_MESH_NY >= 2u && SC_MAX_MESH_NZ >= 2u,
               "a mesh needs at least 2 nodes per axis");
_Static_assert(SC_MAX_NODES <= 65535u * 16u, "node indices must fit 32-bit arithmetic");
_Static_assert(SC_MAX_FEM_NNZ_BLOCKS >= SC_MAX_NODES && SC_MAX_FEM_NNZ_BLOCKS <= 0x7fffffffu,
               "FEM blocks: at least the diagonal, indices in 31 bits");
_Static_assert(SC_HEALTH_MISS_DEGRADED <= SC_HEALTH_MISS_WINDOW, "miss threshold above window");
_Static_assert(SC_HEALTH_MISS_WINDOW <= 64u, "miss window is a 64-bit mask");
_Static_assert(SC_BSCAN_REGIONS_DEFAULT >= 1u && SC_BSCAN_REGIONS_DEFAULT <= SC_BSCAN_MAX_REGIONS,
               "default B-scan region count outside its range");
_Static_assert(SC_MAX_SCAN_LINES >= 2u && SC_MAX_SCAN_LINES <= 65535u &&
                   SC_MAX_SCAN_SAMPLES >= 2u && SC_MAX_SCAN_SAMPLES <= 65535u,
               "scan lines and samples travel as 16-bit numbers");
_Static_assert(SC_BSCAN_TGC_BANDS >= 1u, "at least one TGC band");
_Static_assert(SC_BSCAN_MAX_LINE_EVENTS >= 2u, "a scan line needs an entry and an exit event");
_Static_assert(SC_BSCAN_RANGES >= 1u && SC_BSCAN_RANGES <= SC_MAX_SCAN_LINES,
               "SC_BSCAN_RANGES: 1 .. SC_MAX_SCAN_LINES");
_Static_assert(SC_BSCAN_RANGE_RUNS >= SC_MAX_SCAN_SAMPLES && SC_BSCAN_RANGE_RUNS <= 65535u,
               "a range holds at least one line's runs; run offsets are 16-bit");

_Static_assert(SC_RTCFG_PATH_MAX >= 16u && SC_RTCFG_PATH_MAX < SC_RTCFG_LINE_MAX,
               "a configuration path must fit a configuration line");

/* The console state stream (core/sc_state.h): 1 on, 0 leaves it out of the engine (it costs
 * one record buffer, SC_STATE_RECORD_MAX bytes, plus a few counters). */
#ifndef SC_STATE_STREAM
#define SC_STATE_STREAM 1
#endif

#endif /* SC_CONFIG_H */
