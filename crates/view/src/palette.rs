//! The colours of animats pictures, 0xRRGGBB by kind of part (see
//! `animats_scene::Scene::kinds`): the renderer draws with them and the live
//! view's page receives them with the scene description.

/// Colour of each kind of part; anything else is drawn as `particle`.
pub const PALETTE: [(&str, u32); 10] = [
    ("particle", 0x6fa8dc),
    ("food", 0xffd34d),
    ("roobot", 0xe07b39),
    ("dome", 0xf4a6c8),
    ("tentacle", 0xe58fb5),
    ("seaweed", 0x3f9a4a),
    ("bubble", 0xe8f4ff),
    ("rock", 0x7d7468),
    ("quadruped", 0xb5835a),
    // A jellyfish's translucent bell over its dome masses.
    ("bell", 0xf7b6d2),
];

/// The colour of a part of kind `kind`, 0xRRGGBB.
pub fn colour_of(kind: &str) -> u32 {
    PALETTE
        .iter()
        .find(|(k, _)| *k == kind)
        .unwrap_or(&PALETTE[0])
        .1
}
