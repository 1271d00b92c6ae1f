MODULE PayloadTool
    ! A heavier gripper on the IRB 120 (joulepath example): tGripper2 weighs 1.5 kg with
    ! its centre of gravity 60 mm out along the tool and offset 10 mm in x; the TCP is
    ! 140 mm out. Parts are moved between two nests of a fixture taught in wobjFixture.
    PERS tooldata tGripper2 := [TRUE, [[0, 0, 140], [1, 0, 0, 0]], [1.5, [10, 0, 60], [1, 0, 0, 0], 0.002, 0.002, 0.001]];
    PERS wobjdata wobjFixture := [FALSE, TRUE, "", [[250, -120, 40], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]];
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pNestA := [[0, 0, 60], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pNestB := [[120, 240, 60], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num nUp := 100;

    PROC main()
        MoveAbsJ jHome, v1000, fine, tGripper2;
        WHILE TRUE DO
            Transfer pNestA, pNestB;
            Transfer pNestB, pNestA;
        ENDWHILE
    ENDPROC

    PROC Transfer(robtarget pFrom, robtarget pTo)
        MoveJ Offs(pFrom, 0, 0, nUp), v1000, z50, tGripper2 \WObj:=wobjFixture;
        MoveL pFrom, v200, fine, tGripper2 \WObj:=wobjFixture;
        SetDO doClose, 1;
        WaitTime 0.3;
        MoveL Offs(pFrom, 0, 0, nUp), v500, z20, tGripper2 \WObj:=wobjFixture;
        MoveJ Offs(pTo, 0, 0, nUp), v1000, z20, tGripper2 \WObj:=wobjFixture;
        MoveL pTo, v200, fine, tGripper2 \WObj:=wobjFixture;
        SetDO doClose, 0;
        WaitTime 0.3;
        MoveL Offs(pTo, 0, 0, nUp), v500, z50, tGripper2 \WObj:=wobjFixture;
    ENDPROC
ENDMODULE
