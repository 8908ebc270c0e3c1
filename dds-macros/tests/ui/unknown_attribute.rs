use dds_macros::DdsType;

#[derive(DdsType)]
struct S {
    #[dds(keyy)]
    a: u32,
}

fn main() {}
