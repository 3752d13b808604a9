// Linked-list shadow maps (Ferko 2014), list construction: per-texel linked lists of view
// samples built like the per-pixel linked lists of order-independent transparency (Thibieroz
// and Gruen 2010): one invocation per listed sample takes a node from the pool with an atomic
// counter and links it in front of its texel's list by an atomic exchange of the head pointer.
// The host prepends "#version 430" and LLSM_LOCAL_SIZE.
//
// A node index at or beyond the pool's capacity is not stored: the counter, read back, then
// exceeds the capacity and tells the host which pass overflowed (its unlinked samples go to a
// further pass, none is dropped).
//
// uReset = 1 runs the same items once more to put their texels' heads back to empty, so the
// next pass needs no full clear of the head image.

layout(local_size_x = LLSM_LOCAL_SIZE) in;

// (sample id, texel) per listed sample.
layout(std430, binding = 0) readonly buffer Items { uvec2 items[]; };
// Per texel: the first node of its list, 0xFFFFFFFF when empty.
layout(std430, binding = 1) buffer Heads { uint heads[]; };
// The node pool: (sample id, next node or 0xFFFFFFFF).
layout(std430, binding = 2) writeonly buffer Nodes { uvec2 nodes[]; };
// The pool's atomic counter: nodes asked for.
layout(std430, binding = 3) buffer Counter { uint counter; };

uniform uint uOffset;
uniform uint uCount;
uniform uint uCapacity;
uniform int uReset;

void main()
{
  uint i = gl_GlobalInvocationID.x + uOffset;
  if (i >= uCount)
  {
    return;
  }
  uvec2 item = items[i];
  if (uReset != 0)
  {
    heads[item.y] = 0xFFFFFFFFu;
    return;
  }
  uint node = atomicAdd(counter, 1u);
  if (node >= uCapacity)
  {
    return;
  }
  uint next = atomicExchange(heads[item.y], node);
  nodes[node] = uvec2(item.x, next);
}
