// SpyDecode: decodes every event of an LCM log the way lcm-spy does, headless, for test_spy.py.
// lcm-spy finds a message's Java class by the 8-byte type fingerprint that starts its payload, in its
// own type database (lcm.spy.LCMTypeDatabase, built from the classpath), and decodes it with the
// class's byte[] constructor. Prints (after the database's own "Found N LCM types") one line per
// event, tab-separated: channel, class, then each public non-static field as name=value (arrays as
// [a, b]); "channel<TAB>-" when no class on the classpath matches.
import java.io.DataInputStream;
import java.io.ByteArrayInputStream;
import java.lang.reflect.Field;
import java.lang.reflect.Modifier;
import java.util.Arrays;

public class SpyDecode {
    public static void main(String[] args) throws Exception {
        lcm.spy.LCMTypeDatabase db = new lcm.spy.LCMTypeDatabase();
        lcm.logging.Log log = new lcm.logging.Log(args[0], "r");
        while (true) {
            lcm.logging.Log.Event ev;
            try {
                ev = log.readNext();
            } catch (java.io.EOFException end) {
                break;
            }
            long fingerprint = new DataInputStream(new ByteArrayInputStream(ev.data)).readLong();
            Class<?> cls = db.getClassByFingerprint(fingerprint);
            if (cls == null) {
                System.out.println(ev.channel + "\t-");
                continue;
            }
            Object msg = cls.getConstructor(byte[].class).newInstance((Object) ev.data);
            StringBuilder line = new StringBuilder(ev.channel + "\t" + cls.getName());
            for (Field f : cls.getFields()) {
                if (Modifier.isStatic(f.getModifiers())) {
                    continue;
                }
                Object v = f.get(msg);
                String text = v == null ? "null"
                        : v.getClass().isArray() ? Arrays.deepToString(new Object[] {v}).replaceAll("^\\[|\\]$", "")
                        : v.toString();
                line.append("\t").append(f.getName()).append("=").append(text);
            }
            System.out.println(line);
        }
        log.close();
    }
}
