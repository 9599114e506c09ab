/* bench_bullet_none.c: bench_bullet.h when Bullet (libbullet-dev) was not found at configure
 * time: bb_available() says so and bench-paper leaves Bullet's rows out with a message. */
#include "bench_bullet.h"

#include <stdio.h>

int bb_available(void)
{
    return 0;
}

bb_sim *bb_create(const bb_mesh *m, char *err, size_t errn)
{
    (void)m;
    snprintf(err, errn, "Bullet was not found at configure time (libbullet-dev)");
    return NULL;
}

void bb_set_probe(bb_sim *s, float face_z_mm)
{
    (void)s;
    (void)face_z_mm;
}

void bb_step(bb_sim *s)
{
    (void)s;
}

double bb_max_disp_mm(const bb_sim *s)
{
    (void)s;
    return 0.0;
}

uint32_t bb_links(const bb_sim *s)
{
    (void)s;
    return 0u;
}

void bb_destroy(bb_sim *s)
{
    (void)s;
}
