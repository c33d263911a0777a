// A C# host of libbmlr, as a Unity native plugin calls it: P/Invoke ([DllImport]) with the
// realizer held in a SafeHandle (freed once, also when the host forgets). It realizes a block
// ticked at 60 frames a second, prints the feedback, reads the pose and the face, and checks
// that a malformed block and a panic inside the library come back as errors.
//   mcs Smoke.cs && LD_LIBRARY_PATH=<dir of libbmlr.so> mono Smoke.exe BLOCK.xml
using System;
using System.IO;
using System.Runtime.InteropServices;
using System.Text;

static class Native
{
    const string Lib = "bmlr";
    [DllImport(Lib)] public static extern int bmlr_new(string options, out RealizerHandle r);
    [DllImport(Lib)] public static extern int bmlr_free(IntPtr r);
    [DllImport(Lib)] public static extern int bmlr_perform(RealizerHandle r, byte[] bml);
    [DllImport(Lib)] public static extern int bmlr_tick(RealizerHandle r, double now);
    [DllImport(Lib)] public static extern int bmlr_next_event(RealizerHandle r, out double at, out int has);
    [DllImport(Lib)] public static extern int bmlr_next_feedback(RealizerHandle r, byte[] buf, UIntPtr cap, out UIntPtr len);
    [DllImport(Lib)] public static extern int bmlr_joint_count(RealizerHandle r, out UIntPtr n);
    [DllImport(Lib)] public static extern int bmlr_pose(RealizerHandle r, string character, float[] xyzw, UIntPtr n);
    [DllImport(Lib)] public static extern int bmlr_morph_count(RealizerHandle r, out UIntPtr n);
    [DllImport(Lib)] public static extern int bmlr_morphs(RealizerHandle r, string character, float[] w, UIntPtr n);
    [DllImport(Lib)] public static extern IntPtr bmlr_last_error();
    [DllImport(Lib)] public static extern int bmlr_debug_panic();

    public static string LastError()
    {
        IntPtr p = bmlr_last_error();
        int n = 0;
        while (Marshal.ReadByte(p, n) != 0) n++;
        byte[] bytes = new byte[n];
        Marshal.Copy(p, bytes, 0, n);
        return Encoding.UTF8.GetString(bytes);
    }

    /// A NUL-terminated UTF-8 copy of `s`.
    public static byte[] Utf8(string s)
    {
        return Encoding.UTF8.GetBytes(s + "\0");
    }
}

/// The realizer, freed by the runtime's SafeHandle machinery.
class RealizerHandle : SafeHandle
{
    public RealizerHandle() : base(IntPtr.Zero, true) { }
    public override bool IsInvalid { get { return handle == IntPtr.Zero; } }
    protected override bool ReleaseHandle() { return Native.bmlr_free(handle) == 0; }
}

static class Smoke
{
    static void Check(int status, string what)
    {
        if (status != 0) throw new Exception(what + ": status " + status + ": " + Native.LastError());
    }

    static int Main(string[] args)
    {
        RealizerHandle r;
        Check(Native.bmlr_new("{\"idle\": false}", out r), "bmlr_new");
        using (r)
        {
            Check(Native.bmlr_perform(r, Native.Utf8(File.ReadAllText(args[0]))), "bmlr_perform");
            UIntPtr joints, morphs;
            Check(Native.bmlr_joint_count(r, out joints), "bmlr_joint_count");
            Check(Native.bmlr_morph_count(r, out morphs), "bmlr_morph_count");
            float[] pose = new float[4 * (int)joints];
            float[] face = new float[(int)morphs];
            byte[] buf = new byte[1 << 16];
            int messages = 0;
            float widest = 0;
            for (int k = 0; ; k++)
            {
                Check(Native.bmlr_tick(r, k / 60.0), "bmlr_tick");
                UIntPtr len;
                while (true)
                {
                    Check(Native.bmlr_next_feedback(r, buf, (UIntPtr)buf.Length, out len), "bmlr_next_feedback");
                    if ((ulong)len == 0) break;
                    Console.WriteLine(Encoding.UTF8.GetString(buf, 0, (int)len));
                    messages++;
                }
                Check(Native.bmlr_pose(r, null, pose, (UIntPtr)pose.Length), "bmlr_pose");
                Check(Native.bmlr_morphs(r, "", face, (UIntPtr)face.Length), "bmlr_morphs");
                foreach (float w in face) widest = Math.Max(widest, w);
                double at;
                int has;
                Check(Native.bmlr_next_event(r, out at, out has), "bmlr_next_event");
                if (has == 0) break;
            }
            int malformed = Native.bmlr_perform(r, Native.Utf8("<bml id=\"broken\"><gesture"));
            Console.Error.WriteLine("malformed: status " + malformed + ": " + Native.LastError());
            int panic = Native.bmlr_debug_panic();
            Console.Error.WriteLine("panic: status " + panic + ": " + Native.LastError());
            if (messages == 0 || widest <= 0 || malformed != 4 || panic != 8) return 1;
            Console.Error.WriteLine("smoke: " + messages + " feedback messages, " + joints + " joints, face up to " + widest);
        }
        return 0;
    }
}
