use dds_macros::DdsType;

#[derive(DdsType)]
#[dds(final, discriminator = i16)]
enum U {
    #[dds(case = -1)]
    Neg(u16),
    #[dds(case = 9, case = 10)]
    Nothing,
    #[dds(default)]
    Other(bool),
}

fn main() {}
