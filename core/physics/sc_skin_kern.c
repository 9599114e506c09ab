/* sc_skin_kern.c: the portable variant of the skin's substep (sc_skin_kern.inc). */
#define SC_VEC_W           4u
#define SC_SKIN_SUBSTEP_FN sc_skin_substep_generic
#include "sc_skin_kern.inc"
