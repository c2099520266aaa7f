// Edit records as the journal stores them (the scene store, scene archives, recordings): SceneOp::payload is
// "GSEDIT" + a format version byte + a CBOR map of the record's fields, by name. Named fields let a later
// version add one with a default and still read today's records.
//
// Journals written before these records (version 1) hold the v1 request message of the RPC instead. Their first
// byte is a protobuf tag, never 'G' (0x47 would be wire type 7, which protobuf does not have), so the two cannot be
// confused; reading them needs the API's messages, so the gRPC layer supplies that reader (LegacyEditReader).
#pragma once

#include <functional>
#include <string>

#include "edits/edit_records.h"
#include "world/scene_journal.h"

namespace graspsim::edits {

constexpr int kEditFormatVersion = 2;

// The op a scene journals for `edit`.
SceneOp EncodeEdit(const Edit& edit);

// True when the op's payload is an edit record (any version); false for a version-1 request.
bool IsEditRecord(const SceneOp& op);

// The record of an op that IsEditRecord. Error(kInternal) naming the field for a record that does not parse, or
// whose version is newer than this server's.
Edit DecodeEdit(const SceneOp& op);

// Reads a version-1 op (a serialized request) into its record; throws Error when it cannot.
using LegacyEditReader = std::function<Edit(const SceneOp& op)>;

}  // namespace graspsim::edits
