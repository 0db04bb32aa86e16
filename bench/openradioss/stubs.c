/* Stubs for four open-reader entry points the OpenRadioss starter calls but whose C++
 * sources are absent from the public open_reader snapshot. None of them is used by the
 * peer decks: no rigid parts (Irigid), no /ALE/STRUCTURED_MESH; IS_FILLED only feeds an
 * error message about an element type incompatible with its property. Local build fix
 * for timing the peer decks only. */
#include <stdio.h>
#include <stdlib.h>
#include <stdbool.h>
void cpp_evaluate_rbodies_number_from_rigid_parts_(int *per_part) { (void)per_part; }
void cpp_create_rbodies_from_rigid_parts_(int *to_part, int *ids) { (void)to_part; (void)ids; }
void cpp_is_part_with_elements_(int *id, bool *filled) { (void)id; (void)filled; }
void cpp_sale_mesh_create_(int *message) {
  (void)message;
  fprintf(stderr, "local OpenRadioss build: /ALE/STRUCTURED_MESH is not supported (reader stub)\n");
  exit(2);
}
