MODULE MachineTending
    ! Machine tending on the IRB 120 (joulepath example). The robot takes a blank from the
    ! infeed, loads it into the machine's chuck, waits outside while the machine runs
    ! (6 s) and puts the finished part on the outfeed. The machine's targets are taught
    ! in its work object wobjMachine (a fixed frame 300 mm in front, 250 mm to the right).
    PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];
    PERS wobjdata wobjMachine := [FALSE, TRUE, "", [[300, -250, 50], [1, 0, 0, 0]], [[0, 0, 0], [1, 0, 0, 0]]];
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pInfeed := [[380, 175, 165], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pOutfeed := [[300, 250, 165], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pDoor := [[0, 0, 250], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pChuck := [[0, 0, 110], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num nMachining := 6;

    PROC main()
        MoveAbsJ jHome, v1000, fine, tGripper;
        WHILE TRUE DO
            MoveJ Offs(pInfeed, 0, 0, 100), v1000, z50, tGripper;
            MoveL pInfeed, v300, fine, tGripper;
            WaitTime \InPos, 0.2;
            MoveL Offs(pInfeed, 0, 0, 100), v300, z20, tGripper;
            MoveJ pDoor, v1000, z20, tGripper \WObj:=wobjMachine;
            MoveL pChuck, v200, fine, tGripper \WObj:=wobjMachine;
            WaitTime \InPos, 0.3;
            SetDO doChuckClose, 1;
            MoveL pDoor, v500, z20, tGripper \WObj:=wobjMachine;
            MoveAbsJ jHome, v1000, fine, tGripper;
            PulseDO doCycleStart;
            WaitTime nMachining;
            MoveJ pDoor, v1000, z20, tGripper \WObj:=wobjMachine;
            MoveL pChuck, v200, fine, tGripper \WObj:=wobjMachine;
            SetDO doChuckClose, 0;
            WaitTime \InPos, 0.3;
            MoveL pDoor, v500, z20, tGripper \WObj:=wobjMachine;
            MoveJ Offs(pOutfeed, 0, 0, 100), v1000, z50, tGripper;
            MoveL pOutfeed, v300, fine, tGripper;
            WaitTime 0.2;
            MoveL Offs(pOutfeed, 0, 0, 100), v300, z50, tGripper;
        ENDWHILE
    ENDPROC
ENDMODULE
