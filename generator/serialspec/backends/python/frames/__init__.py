"""The codec's frames: the one generator of the codec's frame code, for every framing the language describes.

A frame shape is a description: the engine's layouts (runtime/framing.py's Layout, made from the model by
backends/common/frames.py), one or more per direction. From it this package writes the codec's frame code, in three
layers, each a case of the one before. Its modules, one concern each:

- `layouts`: which layouts fit the straight-line form, where each element lies, what a direction's functions call
  (a layout with optional elements, `present_if`: the variant without them; a frame with a flag bit set, or a
  message with an optional element's bytes, goes to the engine);
- `decode`: every framing's frame checks and dispatch (layer 1), decode()'s table of frames decoded whole (layer 2),
  and the functions of a direction that keeps the interpreted engine;
- `encode`: every framing's wraps and inline frame encoders, and the length-byte case's encoders;
- `whole`: the length-byte case's whole-frame decoders (decode()'s and the stream parser's);
- `length_byte`: the length-byte case's tables and stream parser format (layer 3);
- `codec`: the codec template's one entry, `frames_codec_context`;
- `engine`: the engine's definitions (Layout, Element, FrameCodec) written into the codec.

1. **Every framing** (`straight_direction`, `decode_lines`, `wrap_parts`, `frame_encoder`): a layout fits the
   straight-line form when its content lies in its one variable part (stuffing, u16 lengths over a span, CRC-16s,
   frames without a header or a length, alternative layouts told apart by their header all do). Each direction
   gets the engine's checks (Layout.unwrap and Layout.wrap) in the engine's order with the engine's messages, but as
   code written for one layout: every offset known when the layout is fixed is a literal, the bytes are unstuffed
   only when a stuffed sequence occurs (a `find` first), a frame's content is decoded in place (no copy) unless it
   was stuffed, and a CRC stored in its own bit order is checked by its residue over the frame. decode() runs the
   checks inline (one call less); encoders of unstuffed frames make their frame inline (`frame_encoder`: the head
   packed with the content's first struct, constant leading bytes as a literal beside the checksummed body). Where a
   layout does not fit (a length after the content, a checksum over bytes inside the stuffed span, ...) the
   direction's two functions call the engine instead, so every layout works and the straight-line form is only ever
   a faster way to the same result (tests/test_straight_frames.py holds them to it).
2. **Frames of one size whose message is one struct's unpack of their content** (`whole_frames`): decode() first
   looks them up by the bytes before the content, checks the rest from the frame's end and unpacks the whole frame.
3. **The length-byte case** (`length_byte_codec_context`): layouts with a header, frame values and a command code
   at fixed offsets, a one-byte length before the content and one checksum at the end, nothing stuffed (the
   model's FrameLayout.classic). Their offsets are known once a frame's first bytes are, so each message of one
   size also gets a whole-frame decoder made from its content decoder's statements (the content size check dropped,
   the cursor made a constant offset), which checks the checksum the cheapest way its algorithm allows
   (checksums/: frame_test, byte_total, byte_table); decode() looks them up by the frame's first bytes
   (`lookup_lines`) before the general checks of layer 1, which take every frame the tables do not. The same
   decoders, at an offset of a buffer (`stream=True`), are the stream parser's (runtime/stream.py's FrameFormat:
   `fixed`, `runs`, `summed`); the others' frames reach the stream parser through the engine (EngineFormat).

`frames_codec_context` is the codec template's one entry. Positions in layer 1 are expressions over `buf`, the
frame with its stuffed span replaced by the plain bytes (`frame` itself where nothing can be stuffed): an element
before the content at a literal offset, an element after it at `end + k`, where `end` is the content's end. Lengths
and checksums that see wire bytes read `frame`.
"""
