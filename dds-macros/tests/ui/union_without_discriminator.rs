use dds_macros::DdsType;

#[derive(DdsType)]
enum U {
    A(u32),
    B(String),
}

fn main() {}
