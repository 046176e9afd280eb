"""The immutable, fully resolved protocol model that every backend reads, one module per concern.

Everything a backend needs is computed here once: sizes, offsets, the content length bounds a stream parser
uses to reject stray headers, class names, and which fields are derived (counts, lengths) rather than given.
Import from `serialspec.lang.model`; the modules are: fields (field kinds and types), sizes, commands (messages and
how replies pair with requests), discriminator (messages picked by a leading constant), framing, examples (and
errata), device, text_frames and protocol.
"""

from serialspec.lang.model.commands import (
    Command as Command,
)
from serialspec.lang.model.commands import (
    Message as Message,
)
from serialspec.lang.model.commands import (
    OptionalWhen as OptionalWhen,
)
from serialspec.lang.model.commands import (
    Selector as Selector,
)
from serialspec.lang.model.commands import (
    Subcommand as Subcommand,
)
from serialspec.lang.model.commands import (
    refusals_of as refusals_of,
)
from serialspec.lang.model.commands import (
    replies_by_request as replies_by_request,
)
from serialspec.lang.model.commands import (
    reply_condition as reply_condition,
)
from serialspec.lang.model.commands import (
    reply_to as reply_to,
)
from serialspec.lang.model.commands import (
    sized_apart as sized_apart,
)
from serialspec.lang.model.commands import (
    sizes_text as sizes_text,
)
from serialspec.lang.model.device import (
    Behaviour as Behaviour,
)
from serialspec.lang.model.device import (
    Device as Device,
)
from serialspec.lang.model.device import (
    DeviceErrors as DeviceErrors,
)
from serialspec.lang.model.device import (
    DeviceKind as DeviceKind,
)
from serialspec.lang.model.device import (
    DeviceModel as DeviceModel,
)
from serialspec.lang.model.device import (
    DeviceTimeout as DeviceTimeout,
)
from serialspec.lang.model.device import (
    ModelEntry as ModelEntry,
)
from serialspec.lang.model.device import (
    Motion as Motion,
)
from serialspec.lang.model.device import (
    Presence as Presence,
)
from serialspec.lang.model.device import (
    Space as Space,
)
from serialspec.lang.model.device import (
    SpaceAccess as SpaceAccess,
)
from serialspec.lang.model.device import (
    Unsolicited as Unsolicited,
)
from serialspec.lang.model.discriminator import (
    Discriminator as Discriminator,
)
from serialspec.lang.model.discriminator import (
    discriminator as discriminator,
)
from serialspec.lang.model.discriminator import (
    leading_constant as leading_constant,
)
from serialspec.lang.model.discriminator import (
    sizing_lead as sizing_lead,
)
from serialspec.lang.model.discriminator import (
    sizing_message as sizing_message,
)
from serialspec.lang.model.discriminator import (
    why_not_picked as why_not_picked,
)
from serialspec.lang.model.examples import (
    Erratum as Erratum,
)
from serialspec.lang.model.examples import (
    ErratumCheck as ErratumCheck,
)
from serialspec.lang.model.examples import (
    Example as Example,
)
from serialspec.lang.model.fields import (
    SCALARS as SCALARS,
)
from serialspec.lang.model.fields import (
    Array as Array,
)
from serialspec.lang.model.fields import (
    BitField as BitField,
)
from serialspec.lang.model.fields import (
    BitPlace as BitPlace,
)
from serialspec.lang.model.fields import (
    Bytes as Bytes,
)
from serialspec.lang.model.fields import (
    Common as Common,
)
from serialspec.lang.model.fields import (
    Count as Count,
)
from serialspec.lang.model.fields import (
    Counted as Counted,
)
from serialspec.lang.model.fields import (
    EnumDef as EnumDef,
)
from serialspec.lang.model.fields import (
    EnumValue as EnumValue,
)
from serialspec.lang.model.fields import (
    Field as Field,
)
from serialspec.lang.model.fields import (
    FlagBit as FlagBit,
)
from serialspec.lang.model.fields import (
    FlagsDef as FlagsDef,
)
from serialspec.lang.model.fields import (
    Group as Group,
)
from serialspec.lang.model.fields import (
    List as List,
)
from serialspec.lang.model.fields import (
    Packed as Packed,
)
from serialspec.lang.model.fields import (
    Scalar as Scalar,
)
from serialspec.lang.model.fields import (
    ScalarType as ScalarType,
)
from serialspec.lang.model.fields import (
    Table as Table,
)
from serialspec.lang.model.fields import (
    TableBlock as TableBlock,
)
from serialspec.lang.model.fields import (
    TableEntry as TableEntry,
)
from serialspec.lang.model.fields import (
    TableValue as TableValue,
)
from serialspec.lang.model.fields import (
    Text as Text,
)
from serialspec.lang.model.fields import (
    Varint as Varint,
)
from serialspec.lang.model.fields import (
    engineering_unit as engineering_unit,
)
from serialspec.lang.model.fields import (
    fixed_bits as fixed_bits,
)
from serialspec.lang.model.framing import (
    VALUE_ROLES as VALUE_ROLES,
)
from serialspec.lang.model.framing import (
    Checksum as Checksum,
)
from serialspec.lang.model.framing import (
    ErrorReply as ErrorReply,
)
from serialspec.lang.model.framing import (
    ExtendedLength as ExtendedLength,
)
from serialspec.lang.model.framing import (
    FrameElement as FrameElement,
)
from serialspec.lang.model.framing import (
    FrameLayout as FrameLayout,
)
from serialspec.lang.model.framing import (
    Framing as Framing,
)
from serialspec.lang.model.framing import (
    Serial as Serial,
)
from serialspec.lang.model.framing import (
    Transparency as Transparency,
)
from serialspec.lang.model.protocol import (
    Protocol as Protocol,
)
from serialspec.lang.model.sizes import (
    MAX_FIXED_SIZE as MAX_FIXED_SIZE,
)
from serialspec.lang.model.sizes import (
    byte_size_expression as byte_size_expression,
)
from serialspec.lang.model.sizes import (
    content_bounds as content_bounds,
)
from serialspec.lang.model.sizes import (
    fixed_size as fixed_size,
)
from serialspec.lang.model.sizes import (
    nul_ended as nul_ended,
)
from serialspec.lang.model.sizes import (
    size_terms as size_terms,
)
from serialspec.lang.model.sizes import (
    sized_by_itself as sized_by_itself,
)
from serialspec.lang.model.sizes import (
    sum_sizes as sum_sizes,
)
from serialspec.lang.model.sizes import (
    takes_rest as takes_rest,
)
from serialspec.lang.model.text_frames import (
    TextAnswer as TextAnswer,
)
from serialspec.lang.model.text_frames import (
    TextDevice as TextDevice,
)
from serialspec.lang.model.text_frames import (
    TextExample as TextExample,
)
from serialspec.lang.model.text_frames import (
    TextField as TextField,
)
from serialspec.lang.model.text_frames import (
    TextFrame as TextFrame,
)
from serialspec.lang.model.text_frames import (
    TextLayout as TextLayout,
)
from serialspec.lang.model.text_frames import (
    TextMessage as TextMessage,
)
from serialspec.lang.model.text_frames import (
    TextRepeat as TextRepeat,
)
from serialspec.runtime.message import Direction as Direction  # the model and the runtime share it
