use dds_macros::DdsType;

#[derive(DdsType)]
#[dds(extensibility = "flexible")]
struct S {
    a: u32,
}

fn main() {}
