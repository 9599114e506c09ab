/* sc_grid_tmpl.h: the cell template of the grid solver (sc_grid.h) as constant tables, for the
 * cell kernels (sc_grid_kern.inc) to unroll; derived from SC_MESH_CELL_TETS, and sc_grid_init
 * checks them against its own derivation. Internal. */
#ifndef SC_GRID_TMPL_H
#define SC_GRID_TMPL_H

#include <stdint.h>

/* edge slots: template corner pairs (a < b) in order of appearance in the tets */
static const uint8_t sc_grid_tmpl_slot[18][2] = {
    {0u, 1u}, {0u, 2u}, {0u, 4u}, {1u, 2u}, {1u, 4u}, {2u, 4u}, {2u, 3u}, {1u, 3u}, {3u, 7u},
    {2u, 7u}, {1u, 7u}, {4u, 5u}, {5u, 7u}, {1u, 5u}, {4u, 7u}, {6u, 7u}, {4u, 6u}, {2u, 6u}};
/* the tets at each template corner: count, then (tet, vertex) */
static const uint8_t sc_grid_tmpl_corner_n[8] = {1u, 4u, 4u, 1u, 4u, 1u, 1u, 4u};
static const uint8_t sc_grid_tmpl_corner_tv[8][4][2] = {
    {{0u, 0u}, {0u, 0u}, {0u, 0u}, {0u, 0u}}, {{0u, 1u}, {1u, 2u}, {2u, 3u}, {4u, 0u}},
    {{0u, 2u}, {1u, 1u}, {3u, 3u}, {4u, 1u}}, {{1u, 0u}, {0u, 0u}, {0u, 0u}, {0u, 0u}},
    {{0u, 3u}, {2u, 1u}, {3u, 2u}, {4u, 2u}}, {{2u, 0u}, {0u, 0u}, {0u, 0u}, {0u, 0u}},
    {{3u, 0u}, {0u, 0u}, {0u, 0u}, {0u, 0u}}, {{1u, 3u}, {2u, 2u}, {3u, 1u}, {4u, 3u}}};
/* the tets at each edge slot: count, then (tet, vertex of slot a, vertex of slot b) */
static const uint8_t sc_grid_tmpl_slot_n[18] = {1u, 1u, 1u, 3u, 3u, 3u, 1u, 1u, 1u,
                                                3u, 3u, 1u, 1u, 1u, 3u, 1u, 1u, 1u};
static const uint8_t sc_grid_tmpl_slot_tv[18][3][3] = {
    {{0u, 0u, 1u}, {0u, 0u, 0u}, {0u, 0u, 0u}}, {{0u, 0u, 2u}, {0u, 0u, 0u}, {0u, 0u, 0u}},
    {{0u, 0u, 3u}, {0u, 0u, 0u}, {0u, 0u, 0u}}, {{0u, 1u, 2u}, {1u, 2u, 1u}, {4u, 0u, 1u}},
    {{0u, 1u, 3u}, {2u, 3u, 1u}, {4u, 0u, 2u}}, {{0u, 2u, 3u}, {3u, 3u, 2u}, {4u, 1u, 2u}},
    {{1u, 1u, 0u}, {0u, 0u, 0u}, {0u, 0u, 0u}}, {{1u, 2u, 0u}, {0u, 0u, 0u}, {0u, 0u, 0u}},
    {{1u, 0u, 3u}, {0u, 0u, 0u}, {0u, 0u, 0u}}, {{1u, 1u, 3u}, {3u, 3u, 1u}, {4u, 1u, 3u}},
    {{1u, 2u, 3u}, {2u, 3u, 2u}, {4u, 0u, 3u}}, {{2u, 1u, 0u}, {0u, 0u, 0u}, {0u, 0u, 0u}},
    {{2u, 0u, 2u}, {0u, 0u, 0u}, {0u, 0u, 0u}}, {{2u, 3u, 0u}, {0u, 0u, 0u}, {0u, 0u, 0u}},
    {{2u, 1u, 2u}, {3u, 2u, 1u}, {4u, 2u, 3u}}, {{3u, 0u, 1u}, {0u, 0u, 0u}, {0u, 0u, 0u}},
    {{3u, 2u, 0u}, {0u, 0u, 0u}, {0u, 0u, 0u}}, {{3u, 3u, 0u}, {0u, 0u, 0u}, {0u, 0u, 0u}}};
/* the 26 real targets: kind (0 corner, 1 grid edge, 2 face), axis or plane, corner, source
 * slot per parity, transposed per parity */
static const uint8_t sc_grid_tmpl_target[26][7] = {
    {0u, 0u, 0u, 0u, 1u, 0u, 0u},   {0u, 0u, 1u, 1u, 0u, 0u, 0u},   {0u, 0u, 2u, 2u, 3u, 0u, 0u},
    {0u, 0u, 3u, 3u, 2u, 0u, 0u},   {0u, 0u, 4u, 4u, 5u, 0u, 0u},   {0u, 0u, 5u, 5u, 4u, 0u, 0u},
    {0u, 0u, 6u, 6u, 7u, 0u, 0u},   {0u, 0u, 7u, 7u, 6u, 0u, 0u},   {1u, 0u, 0u, 0u, 0u, 0u, 1u},
    {1u, 0u, 2u, 6u, 6u, 0u, 1u},   {1u, 0u, 4u, 11u, 11u, 0u, 1u}, {1u, 0u, 6u, 15u, 15u, 0u, 1u},
    {1u, 1u, 0u, 1u, 7u, 0u, 0u},   {1u, 1u, 1u, 7u, 1u, 0u, 0u},   {1u, 1u, 4u, 16u, 12u, 0u, 0u},
    {1u, 1u, 5u, 12u, 16u, 0u, 0u}, {1u, 2u, 0u, 2u, 13u, 0u, 0u},  {1u, 2u, 1u, 13u, 2u, 0u, 0u},
    {1u, 2u, 2u, 17u, 8u, 0u, 0u},  {1u, 2u, 3u, 8u, 17u, 0u, 0u},  {2u, 0u, 0u, 3u, 3u, 0u, 0u},
    {2u, 0u, 4u, 14u, 14u, 0u, 0u}, {2u, 1u, 0u, 4u, 4u, 0u, 0u},   {2u, 1u, 2u, 9u, 9u, 0u, 0u},
    {2u, 2u, 0u, 5u, 10u, 0u, 0u},  {2u, 2u, 1u, 10u, 5u, 0u, 0u}};

/* write_cell's pairs of targets one node apart in one row family (kind and axis; corners c + 1
 * and c, same group): per target of a pair the other one, else 0xff. The walk writes the upper
 * one (odd corner) first, so a row's two vectors at node offsets 1 and 0 overlap in all but one
 * lane: written as one (write_cell), not a load waiting on the store just before it. */
static const uint8_t sc_grid_tmpl_pair[26] = {
    1u,  0u,  3u,  2u,  5u,  4u,  7u,  6u,    0xffu, 0xffu, 0xffu, 0xffu, 13u,
    12u, 15u, 14u, 17u, 16u, 19u, 18u, 0xffu, 0xffu, 0xffu, 0xffu, 25u,   24u};

/* the template entries computed together (kind 0 corner or 1 edge slot, entry, entry; one entry
 * twice where it feeds its targets alone): every target's two sources, src0 and src1, lie in one
 * group, so write_cell computes each entry once and writes its targets from registers */
#define SC_GRID_TMPL_GROUPS 17u
static const uint8_t sc_grid_tmpl_group[SC_GRID_TMPL_GROUPS][3] = {
    {0u, 0u, 1u},   {0u, 2u, 3u},   {0u, 4u, 5u}, {0u, 6u, 7u},   {1u, 0u, 0u},  {1u, 6u, 6u},
    {1u, 11u, 11u}, {1u, 15u, 15u}, {1u, 1u, 7u}, {1u, 16u, 12u}, {1u, 2u, 13u}, {1u, 17u, 8u},
    {1u, 3u, 3u},   {1u, 14u, 14u}, {1u, 4u, 4u}, {1u, 9u, 9u},   {1u, 5u, 10u}};

#endif /* SC_GRID_TMPL_H */
